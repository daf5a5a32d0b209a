"""COCO keypoint OKS and AP/AR against pycocotools' COCOeval (iouType 'keypoints') on the same
annotation and result files: a perfect and a perturbed result, several images, two categories,
a crowd annotation, a truth without labelled keypoints, small / medium / large areas, false
positives and tied scores."""
from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval

from recon_eval.metrics.objects_coco import KeypointDetection, KeypointTruth, keypoint_ap, oks

N_KP = 5
SIGMAS = np.array([0.25, 0.35, 0.5, 0.72, 1.07]) / 10.0


def _truths(rng):
    anns, ann_id = [], 1
    for image_id in (1, 2, 3, 4):
        for _ in range(3):
            size = float(rng.choice([20.0, 60.0, 150.0]))
            x, y = rng.uniform(0, 300, 2)
            kp = np.column_stack([x + rng.uniform(0, size, N_KP), y + rng.uniform(0, size, N_KP),
                                  rng.choice([0, 1, 2], N_KP, p=[0.2, 0.3, 0.5])])
            anns.append({"id": ann_id, "image_id": image_id, "category_id": int(rng.choice([1, 2])),
                         "keypoints": kp.ravel().tolist(), "num_keypoints": int(np.count_nonzero(kp[:, 2] > 0)),
                         "bbox": [float(x), float(y), size, size], "area": size * size * 0.8, "iscrowd": 0})
            ann_id += 1
    anns[4]["iscrowd"] = 1
    anns[7]["keypoints"][2::3] = [0] * N_KP  # no labelled keypoint: ignored truth
    anns[7]["num_keypoints"] = 0
    return anns


def _results(anns, rng, sigma_px: float):
    res = []
    for a in anns:
        kp = np.asarray(a["keypoints"], dtype=np.float64).reshape(-1, 3).copy()
        kp[:, :2] += rng.normal(0, sigma_px, (N_KP, 2)) if sigma_px else 0
        kp[:, 2] = 1
        res.append({"image_id": a["image_id"], "category_id": a["category_id"], "keypoints": kp.ravel().tolist(),
                    "score": float(np.round(rng.uniform(0.2, 1), 1))})  # rounded: ties
    res.append({"image_id": 2, "category_id": 1, "keypoints": (rng.uniform(0, 300, (N_KP, 3))).ravel().tolist(),
                "score": 0.95})  # a confident false positive
    return res


def _coco_eval(tmp_path, anns, res):
    gt = {"images": [{"id": i, "width": 400, "height": 400} for i in (1, 2, 3, 4)], "annotations": anns,
          "categories": [{"id": c, "name": f"c{c}", "keypoints": [f"k{j}" for j in range(N_KP)], "skeleton": []}
                         for c in (1, 2)]}
    (tmp_path / "gt.json").write_text(json.dumps(gt))
    (tmp_path / "res.json").write_text(json.dumps(res))
    with contextlib.redirect_stdout(io.StringIO()):
        coco_gt = COCO(str(tmp_path / "gt.json"))
        coco_dt = coco_gt.loadRes(str(tmp_path / "res.json"))
        ev = COCOeval(coco_gt, coco_dt, "keypoints")
        ev.params.kpt_oks_sigmas = SIGMAS
        ev.evaluate()
        ev.accumulate()
        ev.summarize()
    return ev


def _ours(anns, res):
    truths = [KeypointTruth(a["id"], a["image_id"], a["category_id"], np.reshape(a["keypoints"], (-1, 3)),
                            tuple(a["bbox"]), a["area"], bool(a["iscrowd"]), a["num_keypoints"]) for a in anns]
    dets = [KeypointDetection(r["image_id"], r["category_id"], np.reshape(r["keypoints"], (-1, 3)), r["score"])
            for r in res]
    return truths, dets


@pytest.mark.parametrize("sigma_px", [0.0, 2.5])
def test_keypoint_ap_and_oks_equal_cocoeval(tmp_path, sigma_px, agreement):
    rng = np.random.default_rng(7)
    anns = _truths(rng)
    res = _results(anns, rng, sigma_px)
    ev = _coco_eval(tmp_path, anns, res)
    truths, dets = _ours(anns, res)
    ours = keypoint_ap(truths, dets, sigmas=SIGMAS, image_ids=[1, 2, 3, 4])
    d_stats = float(np.max(np.abs(np.array(ours.stats()) - np.array(ev.stats))))
    d_oks = 0.0
    for (image_id, cat), theirs in ev.ious.items():
        if len(theirs) == 0:
            continue
        g = [t for t in truths if (t.image_id, t.category_id) == (image_id, cat)]
        d = sorted([x for x in dets if (x.image_id, x.category_id) == (image_id, cat)], key=lambda x: -x.score)
        d_oks = max(d_oks, float(np.max(np.abs(oks(d, g, SIGMAS) - theirs))))
    kind = "perfect" if sigma_px == 0 else "perturbed"
    agreement(f"coco.keypoints.{kind}", "COCO keypoint AP/AR stats (10) and OKS", "pycocotools COCOeval",
              "2.0.11", f"12 truths in 4 images, {kind} result + a false positive", max(d_stats, d_oks))
    assert d_stats == 0 and d_oks == 0
    assert ours.ap > 0.5 and (ours.ap < 1 if sigma_px else True)
