"""BOP19 average recall (docs/metrics.md, "Object pose"): the error loop of bop_toolkit's
``scripts/eval_calc_errors.py``, the greedy matching of ``pose_matching.py``, the recall of
``score.calc_localization_scores`` and the averaging of ``scripts/eval_bop19_pose.py``
(thodan/bop_toolkit, commit cea62d6), localization mode as the BOP19 tasks run it:

* targets ``(scene_id, im_id, obj_id, inst_count)`` (``test_targets_bop19.json``); per target the
  ``inst_count`` highest-scored estimates are scored (``n_top = -1``; ties keep file order);
* ``visib_gt_min = -1``: the valid truths of a target are its ``inst_count`` most visible ones;
* each estimate, in decreasing score, takes the unmatched valid truth of its object with the
  smallest error below the threshold (strict ``<``);
* recall = matched valid truths / valid truths, pooled over all images; the average recall of an
  error is the mean recall over its thresholds (VSD: 10 taus x 10 thresholds; MSSD: 0.05..0.5 of
  the diameter; MSPD: 5..50 px scaled by 640 / image width), and AR is the mean of the three.

ADD and ADD-S recall use the same matching at 0.1 of the diameter (``eval_calc_scores.py``'s
``add``/``adi`` threshold). Errors in the model's units (BOP: mm) and pixels.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

#: eval_bop19_pose.py's thresholds, built exactly as it builds them (np.arange floats).
VSD_TAUS = tuple(np.arange(0.05, 0.51, 0.05))
VSD_THRESHOLDS = tuple(np.arange(0.05, 0.51, 0.05))
MSSD_THRESHOLDS = tuple(np.arange(0.05, 0.51, 0.05))  # fractions of the diameter
MSPD_THRESHOLDS = tuple(np.arange(5, 51, 5))  # px at a 640 px wide image
ADD_THRESHOLD = 0.1  # eval_calc_scores.py correct_th "add" / "adi", fraction of the diameter
MSPD_REFERENCE_WIDTH_PX = 640.0  # eval_calc_scores.py: errors scaled by 640 / image width


@dataclass(frozen=True)
class PoseEstimate:
    """One line of a BOP19 result CSV: ``cam_from_model`` R (3, 3), t (3,) in model units."""

    scene_id: int
    im_id: int
    obj_id: int
    score: float
    R: np.ndarray
    t: np.ndarray
    time_s: float


@dataclass(frozen=True)
class GtPose:
    """One ``scene_gt.json`` entry with its ``scene_gt_info.json`` visible fraction."""

    obj_id: int
    R: np.ndarray
    t: np.ndarray
    visib_fract: float


@dataclass(frozen=True)
class Target:
    scene_id: int
    im_id: int
    obj_id: int
    inst_count: int


@dataclass(frozen=True)
class EstimateErrors:
    """The errors of one scored estimate against every truth of its object in its image."""

    scene_id: int
    im_id: int
    obj_id: int
    est_id: int  # index among the (scene, image, object)'s estimates in file order
    score: float
    errors: dict  # gt_id -> tuple of error values (VSD: one per tau)


#: error(estimate, truth, (scene_id, im_id)) -> tuple of values
ErrorFn = Callable[[PoseEstimate, GtPose, tuple], tuple]


def estimate_errors(error: ErrorFn, estimates, targets, gts: dict) -> list[EstimateErrors]:
    """eval_calc_errors.py's loop: ``gts`` maps (scene_id, im_id) to the image's truths in
    ``scene_gt.json`` order (gt_id = index)."""
    by_obj: dict = {}
    for e in estimates:
        by_obj.setdefault((e.scene_id, e.im_id, e.obj_id), []).append(e)
    out = []
    for tg in targets:
        key = (tg.scene_id, tg.im_id)
        ests = by_obj.get((tg.scene_id, tg.im_id, tg.obj_id), [])
        ranked = sorted(enumerate(ests), key=lambda x: x[1].score, reverse=True)[: tg.inst_count]
        for est_id, est in ranked:
            errs = {gid: tuple(error(est, g, key)) for gid, g in enumerate(gts[key]) if g.obj_id == tg.obj_id}
            out.append(EstimateErrors(tg.scene_id, tg.im_id, tg.obj_id, est_id, est.score, errs))
    return out


def valid_truths(targets, gts: dict) -> dict:
    """(scene_id, im_id) -> per-gt validity: a target's ``inst_count`` most visible truths
    (eval_calc_scores.py with ``visib_gt_min = -1``)."""
    to_add: dict = {}
    for tg in targets:
        to_add.setdefault((tg.scene_id, tg.im_id), {})[tg.obj_id] = tg.inst_count
    valid = {}
    for key, counts in to_add.items():
        im_gts, left = gts[key], dict(counts)
        flags = [False] * len(im_gts)
        for gid in sorted(range(len(im_gts)), key=lambda g: im_gts[g].visib_fract, reverse=True):
            oid = im_gts[gid].obj_id
            if left.get(oid, 0) > 0:
                flags[gid] = True
                left[oid] -= 1
        valid[key] = flags
    return valid


def matched_count(errors: list[EstimateErrors], valid: dict, threshold: float, index: int = 0,
                  scale: Callable[[EstimateErrors], float] = lambda e: 1.0) -> int:
    """pose_matching.match_poses over every (image, object): how many valid truths an estimate
    matches with ``error[index] * scale(estimate) < threshold``."""
    groups: dict = {}
    for e in errors:
        groups.setdefault((e.scene_id, e.im_id, e.obj_id), []).append(e)
    n = 0
    for (scene_id, im_id, _), group in groups.items():
        flags, matched = valid[(scene_id, im_id)], set()
        for e in sorted(group, key=lambda x: x.score, reverse=True):
            best, best_err = -1, threshold
            s = scale(e)
            for gid, err in e.errors.items():
                v = err[index] * s
                if flags[gid] and gid not in matched and v < best_err:
                    best, best_err = gid, v
            if best >= 0:
                matched.add(best)
                n += 1
    return n


@dataclass(frozen=True)
class RecallCurve:
    thresholds: tuple  # per recall (VSD: tau-major, then threshold)
    recalls: tuple
    average_recall: float


def recall_curve(errors, valid: dict, thresholds, *, n_values: int = 1, scale=lambda e: 1.0) -> RecallCurve:
    """Recall at each threshold for each of the ``n_values`` error values (VSD's taus), and
    their mean. Truth count = valid truths (0 -> recall 0, as ``score.calc_recall``)."""
    n_targets = sum(sum(f) for f in valid.values())
    ths, recalls = [], []
    for i in range(n_values):
        for th in thresholds:
            ths.append(float(th))
            recalls.append(matched_count(errors, valid, th, i, scale) / float(n_targets) if n_targets else 0.0)
    return RecallCurve(tuple(ths), tuple(recalls), float(np.mean(recalls)))


@dataclass(frozen=True)
class Bop19Result:
    ar: float  # bop19_average_recall = mean(ar_vsd, ar_mssd, ar_mspd)
    ar_vsd: float
    ar_mssd: float
    ar_mspd: float
    add_recall: float  # ADD < 0.1 diameter
    adds_recall: float  # ADD-S < 0.1 diameter
    ad_recall: float  # bop_toolkit "ad": ADD-S for models that declare a symmetry, ADD otherwise
    n_targets: int  # valid truths
    n_estimates: int  # estimates in the result
    n_scored: int  # estimates scored (the top inst_count per target)
    mean_time_per_image_s: float  # -1 when any image's time is negative (BOP: not available)
    vsd: RecallCurve
    mssd: RecallCurve
    mspd: RecallCurve


def mean_time_per_image(estimates) -> float:
    """eval_bop19_pose.py's average time per image: one time per image (the mean of its lines'
    times here; BOP rejects unequal ones), -1 when any is negative or there is no estimate."""
    times: dict = {}
    for e in estimates:
        times.setdefault((e.scene_id, e.im_id), []).append(e.time_s)
    if not times or any(t < 0 for ts in times.values() for t in ts):
        return -1.0
    return float(np.mean([np.mean(ts) for ts in times.values()]))
