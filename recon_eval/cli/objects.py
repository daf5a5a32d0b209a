"""``recon-eval objects``: 6D object poses in BOP's result CSV and keypoints in COCO's result
format against a BOP dataset and a COCO keypoint annotation file (docs/metrics.md, "Object pose",
"Keypoints"): BOP19 AR (VSD, MSSD, MSPD), ADD / ADD-S recall, COCO keypoint AP/AR, PCK."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.cli.scored import scored
from recon_eval.errors import InputError
from recon_eval.metrics.objects_bop_eval import VSD_DELTA_MM, bop19_evaluate
from recon_eval.metrics.objects_coco import keypoint_ap, oks
from recon_eval.metrics.objects_parts import PCK_ALPHAS, PckResult, pck
from recon_eval.readers.bop import read_bop_dataset, read_bop_results
from recon_eval.readers.coco import read_coco_keypoint_results, read_coco_keypoint_truth
from recon_eval.report import plots
from recon_eval.report.html import Figure

#: Where a dataset folder keeps its exports (scenegen's BOP and COCO writers), tried in order.
BOP_FOLDERS = (".", "bop", "export/bop")
COCO_FILES = ("coco_keypoints.json", "coco/keypoints.json", "export/coco/keypoints.json", "coco/annotations.json",
              "export/coco/annotations.json")


def arguments(p) -> None:
    p.add_argument("gt", help="BOP dataset (or split / scene) folder, or a dataset folder holding its BOP export "
                              f"({', '.join(BOP_FOLDERS[1:])}) and COCO export ({', '.join(COCO_FILES)})")
    p.add_argument("--bop", metavar="CSV", help="pose result in BOP19's CSV format "
                                                "(scene_id,im_id,obj_id,score,R,t,time; R row-major, t in mm)")
    p.add_argument("--coco", metavar="JSON", help="keypoint result in COCO's results format")
    p.add_argument("--coco-gt", metavar="JSON", help="the COCO keypoint annotation file (default: found under GT)")
    p.add_argument("--kpt-sigmas", type=float, nargs="+", metavar="S",
                   help="OKS sigmas for categories that declare none: one value for every keypoint or one per "
                        "keypoint (default: COCO's 17 person sigmas for a 17-keypoint category, else required)")
    p.add_argument("--vsd-delta", type=float, default=VSD_DELTA_MM,
                   help=f"VSD visibility tolerance in mm (eval_bop19_pose.py: {VSD_DELTA_MM:g}; ITODD 5)")


def _bop_root(gt: Path) -> Path:
    for d in BOP_FOLDERS:
        c = gt / d
        if (c / "models").is_dir() or (c / "models_eval").is_dir() or (c / "scene_gt.json").is_file() \
                or (c / "test").is_dir():
            return c
    raise InputError(f"{gt}: no BOP dataset here or under {', '.join(BOP_FOLDERS[1:])}")


def _coco_file(a) -> Path:
    if a.coco_gt:
        return Path(a.coco_gt)
    gt = Path(a.gt)
    for f in COCO_FILES:
        if (gt / f).is_file():
            return gt / f
    raise InputError(f"{gt}: no COCO keypoint annotation file under it ({', '.join(COCO_FILES)}); give --coco-gt")


def pck_pairs(truths, dets, sigmas):
    """Each scored truth paired with the detection of its image and category of highest OKS (each
    detection used once; truths taken in file order): predicted and truth xy (N, K, 2), labelled
    (N, K), the truth box's max(w, h) (N,). An unpaired truth has NaN predictions (wrong)."""
    by_key: dict = {}
    for d in dets:
        by_key.setdefault((d.image_id, d.category_id), []).append(d)
    used, pred, gt, lab, size = set(), [], [], [], []
    for t in truths:
        if t.iscrowd:
            continue
        cands = [d for d in by_key.get((t.image_id, t.category_id), []) if id(d) not in used]
        best = None
        if cands:
            s = oks(cands, [t], sigmas[t.category_id])[:, 0]
            best = cands[int(np.argmax(s))]
            used.add(id(best))
        pred.append(best.keypoints[:, :2] if best is not None else np.full((len(t.keypoints), 2), np.nan))
        gt.append(t.keypoints[:, :2])
        lab.append(t.keypoints[:, 2] > 0)
        size.append(max(t.bbox[2], t.bbox[3]))
    return np.array(pred), np.array(gt), np.array(lab, dtype=bool), np.array(size)


def pck_pooled(groups) -> PckResult:
    """PCK over groups of (pred, gt, labelled, size) with different keypoint counts: one
    keypoint list, each keypoint with its instance's reference size."""
    pred, gt, lab, size = [], [], [], []
    for p, g, lb, sz in groups:
        if len(p) == 0:
            continue
        pred.append(p.reshape(-1, 2))
        gt.append(g.reshape(-1, 2))
        lab.append(lb.reshape(-1))
        size.append(np.repeat(sz, lb.shape[1]))
    if not pred:
        return pck(np.zeros((0, 1, 2)), np.zeros((0, 1, 2)), np.zeros((0, 1), bool), np.zeros(0), alphas=PCK_ALPHAS)
    return pck(np.concatenate(pred)[:, None], np.concatenate(gt)[:, None], np.concatenate(lab)[:, None],
               np.concatenate(size), alphas=PCK_ALPHAS)


def score(a):
    if not a.bop and not a.coco:
        raise InputError("objects: give a pose result (--bop CSV) and/or a keypoint result (--coco JSON)")
    gt = Path(a.gt)
    if not gt.is_dir():
        raise InputError(f"{gt}: not a folder (expected a BOP dataset or a dataset with its BOP/COCO export)")
    res, inputs = {}, {"gt": a.gt, "bop": a.bop, "coco": a.coco}
    if a.bop:
        ds = read_bop_dataset(_bop_root(gt))
        ests = read_bop_results(a.bop)
        unknown = sorted({(e.scene_id, e.im_id) for e in ests} - set(ds.gts))
        if unknown:
            raise InputError(f"{a.bop}: scene {unknown[0][0]} image {unknown[0][1]} is not in the truth ({ds.split})")
        res["bop19"] = bop19_evaluate(ests, ds.targets, ds.gts, ds.views, ds.models, vsd_delta=a.vsd_delta)
        inputs.update(bop_dataset=str(ds.split), targets=ds.targets_source, vsd_delta_mm=a.vsd_delta,
                      vsd_depth_render="recon_eval ray-plane rasteriser (bop_toolkit: OpenGL)")
    if a.coco:
        cf = _coco_file(a)
        truth = read_coco_keypoint_truth(cf, a.kpt_sigmas)
        dets = read_coco_keypoint_results(a.coco, truth.image_ids, {c: len(s) for c, s in truth.sigmas.items()})
        res["coco_keypoints"] = keypoint_ap(truth.truths, dets, sigmas=truth.sigmas, image_ids=truth.image_ids)
        pairs = {}  # PCK per category (keypoint counts differ), pooled
        for c in truth.sigmas:
            pairs[c] = pck_pairs([t for t in truth.truths if t.category_id == c],
                                 [d for d in dets if d.category_id == c], truth.sigmas)
        res["pck"] = pck_pooled(pairs.values())
        inputs.update(coco_gt=str(cf), kpt_sigmas=truth.sigmas_source,
                      pck="highest-OKS detection per truth, threshold alpha * max(box w, h), <=")

    def figures():
        out = []
        if "bop19" in res:
            r = res["bop19"]
            for name, c, unit in (("MSSD", r.mssd, "fraction of the diameter"), ("MSPD", r.mspd, "px at 640 px width")):
                out.append(Figure(f"{name} recall", plots.metric_vs_figure(
                    c.thresholds, {f"{name} recall": c.recalls}, xlabel=f"threshold ({unit})", ylabel="recall",
                    title=f"AR_{name} = {c.average_recall:.3f}")))
        return out

    return inputs, res, figures


def headline(a, res) -> dict:
    m = {}
    if "bop19" in res:
        r = res["bop19"]
        m.update({"bop19_ar": r.ar, "bop19_ar_vsd": r.ar_vsd, "bop19_ar_mssd": r.ar_mssd, "bop19_ar_mspd": r.ar_mspd,
                  "add_recall": r.add_recall, "adds_recall": r.adds_recall})
    if "coco_keypoints" in res:
        m.update({"coco_kp_ap": res["coco_keypoints"].ap, "coco_kp_ap50": res["coco_keypoints"].ap50})
        # pck_10 = PCK at alpha 0.10 (no dot: metric paths split on dots)
        m.update({f"pck_{round(al * 100):02d}": v for al, v in zip(res["pck"].alphas, res["pck"].pck)})
    return m


COMMANDS = {"objects": scored(arguments, score, headline)}
