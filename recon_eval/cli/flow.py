"""``recon-eval flow``: optical flow against a truth flow file or a dataset's flow and
correspondences with their occlusion states (docs/metrics.md, "Optical flow"). Flow formats:
:func:`recon_eval.readers.flow.read_flow`."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.cli.common import stderr_progress
from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.flow import flow_metrics
from recon_eval.readers.flow import FLOW_SUFFIXES, read_flow
from recon_eval.readers.kitti_png import read_kitti_obj_map
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from scenegen.dataset.crossview import OCCLUDED, VISIBLE


def arguments(p) -> None:
    p.add_argument("est", help="estimated flow (.flo, KITTI .png, .npy, .pfm), or with a dataset truth a folder of "
                               "<view1>__<view2>.<ext> files (every flow pair of the dataset)")
    p.add_argument("gt", help="truth flow file, or a dataset folder (its flow files and correspondences)")
    p.add_argument("--views", nargs=2, metavar=("VIEW1", "VIEW2"),
                   help="dataset truth: the pair of a single estimate file (flow from VIEW1 to VIEW2)")
    p.add_argument("--gt-noc", help="file truth: the non-occluded truth flow (KITTI flow_noc); pixels valid there "
                                    "are non-occluded")
    p.add_argument("--obj-map", help="file truth: KITTI foreground map PNG (Fl-fg)")
    p.add_argument("--fg-object", action="append",
                   help="dataset truth: spec object(s) whose pixels in VIEW1 are foreground (Fl-fg)")


def _dataset_pairs(a, ds):
    """[(estimate, truth flow, states, foreground, (i, j), source)], views without estimates."""
    if Path(a.est).is_dir():
        if a.views:
            pairs = [tuple(a.views)]
        else:
            pairs = list(ds.flow_pairs()) or list(ds.crossview_pairs())
            if not pairs:
                raise InputError(f"{a.gt}: crossview/index.json: no flow or crossview pairs to score")
    else:
        if not a.views:
            raise InputError(f"{a.est}: one estimate file scores one pair: pass --views VIEW1 VIEW2")
        pairs = [tuple(a.views)]
    fg_ids = [ds.object_id(n) for n in (a.fg_object or [])]
    out, missing = [], []
    progress = stderr_progress("flow pairs")
    for n, (i, j) in enumerate(pairs):
        progress(n + 1, len(pairs))
        g, st, source = ds.flow_truth(i, j)
        if Path(a.est).is_dir():
            f = next((Path(a.est) / f"{i}__{j}{s}" for s in FLOW_SUFFIXES if (Path(a.est) / f"{i}__{j}{s}").is_file()),
                     None)
            if f is None:
                missing.append(f"{i}__{j}")
                e = np.full_like(g, np.nan)
            else:
                e = read_flow(f)
        else:
            e = read_flow(a.est)
        if e.shape != g.shape:
            raise InputError(f"{a.est}: flow shape {e.shape} differs from the truth's {g.shape} ({i} -> {j})")
        fg = np.isin(ds.object_ids(i), fg_ids) if fg_ids else None
        out.append((e, g, st, fg, (i, j), source))
    return out, missing


def score(a):
    missing = []
    if is_dataset(a.gt):
        ds = read_dataset(a.gt)
        items, missing = _dataset_pairs(a, ds)
        gt_kind = "scenegen-dataset flow / correspondences (occlusion states from crossview/corr)"
    else:
        if a.views or a.fg_object:
            raise InputError("--views and --fg-object need a dataset truth")
        e, g = read_flow(a.est), read_flow(a.gt)
        if e.shape != g.shape:
            raise InputError(f"{a.est}: flow shape {e.shape} differs from the truth's {g.shape} ({a.gt})")
        st = None
        if a.gt_noc:
            noc = read_flow(a.gt_noc)
            st = np.where(np.all(np.isfinite(noc), axis=2), VISIBLE, OCCLUDED).astype(np.uint8)
        fg = read_kitti_obj_map(a.obj_map) if a.obj_map else None
        items, gt_kind = [(e, g, st, fg, None, a.gt)], "file"
    fgs = [it[3] for it in items]
    res = {"flow": flow_metrics([it[0] for it in items], [it[1] for it in items], [it[2] for it in items],
                                None if all(f is None for f in fgs) else
                                [np.zeros(it[1].shape[:2], bool) if f is None else f for it, f in zip(items, fgs)])}
    inputs = {"est": a.est, "gt": a.gt, "gt_kind": gt_kind,
              "pairs": [f"{it[4][0]}__{it[4][1]}" for it in items if it[4] is not None] or None,
              "truth_sources": [it[5] for it in items], "pairs_without_estimate": missing,
              "pairs_without_occlusion_truth": [f"{it[4][0]}__{it[4][1]}" if it[4] else a.gt for it in items
                                                if it[2] is None], "fg_object": a.fg_object}
    return inputs, res, no_figures


COMMANDS = {"flow": scored(arguments, score)}
