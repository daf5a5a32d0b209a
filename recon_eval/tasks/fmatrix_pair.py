"""Scoring a fundamental matrix against a dataset pair: the truth F, the truth correspondences
and the relative pose of two views, in the pixels the estimate is for (docs/metrics.md,
"Fundamental matrices and homographies").

A fundamental matrix exists only for UNDISTORTED pixels (``x = K (X/Z, Y/Z, 1)``); the dataset
stores that F (``crossview/twoview/<i>/<j>.json``, else it is ``K2^-T [t]x R K1^-1`` of
cameras.json). An estimate is scored in one of :data:`PIXELS`:

* ``undistorted``: the estimate is for undistorted pixels (the user undistorted the images or the
  points with the calibration first, as OpenCV's two-view pipeline does). The truth
  correspondences are undistorted with the exact inverse of the dataset's camera model; Zhang's
  F-distance to the truth F and the pose via K are scored.
* ``distorted``: the estimate is for the raw pixels of the images as stored. The truth
  correspondences are left raw; for a camera with distortion no truth F exists in those pixels
  (no F-distance; the note says so) and the pose via K is that of ``E = K2^T F K1`` applied to raw
  pixels: what a user of that F would get. For two pinhole cameras both are the same pixels.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.epipolar import (
    fundamental_metrics,
    inlier_precision_recall,
    pose_error_from_fundamental,
    zhang_f_distance,
)
from scenegen.geometry.twoview import undistorted_pixels

#: What pixels an estimated F is for.
PIXELS = ("undistorted", "distorted")


@dataclass(frozen=True)
class PairTruth:
    """The truth of one dataset pair in the chosen pixels: correspondences x1 <-> x2 (N, 2) px,
    the truth F (None where none exists in these pixels), K1, K2 and cam2_from_cam1 (R, t)."""

    x1: np.ndarray
    x2: np.ndarray
    F_gt: np.ndarray | None
    K1: np.ndarray
    K2: np.ndarray
    R: np.ndarray
    t: np.ndarray
    size1: tuple
    size2: tuple
    pixels: str
    notes: dict


def pair_truth(ds, view1: str, view2: str, *, pixels: str, max_points: int = 20000,
               correspondences: bool = True) -> PairTruth:
    """The :class:`PairTruth` of ``view1 -> view2`` of the dataset ``ds`` (a
    :class:`recon_eval.readers.scenegen_dataset.DatasetTruth`), in ``pixels`` (:data:`PIXELS`);
    without ``correspondences`` (the caller has its own) x1 and x2 are empty (0, 2)."""
    if pixels not in PIXELS:
        raise InputError(f"pixels: expected one of {', '.join(PIXELS)}, got {pixels!r}")
    (c1, p1), (c2, p2) = ds.camera(view1), ds.camera(view2)
    rel = p2 @ p1.inverse()  # cam2_from_cam1
    F_und, source = ds.truth_fundamental(view1, view2)
    if F_und is None:
        raise InputError(f"{ds.root}: views {view1!r} and {view2!r} share one camera centre: no fundamental matrix")
    if correspondences:
        x1, x2 = ds.correspondences(view1, view2, max_points=max_points)
        if len(x1) == 0:
            raise InputError(f"{ds.root}: views {view1!r} and {view2!r} share no visible truth point")
    else:
        x1 = x2 = np.zeros((0, 2))
    distorted_cams = not (c1.model == "pinhole" and c2.model == "pinhole")
    notes = {"pixels": pixels, "cameras": f"{c1.model} / {c2.model}",
             "correspondences": f"dataset truth correspondences ({len(x1)} visible, seeded sample)"}
    F_gt = F_und
    if pixels == "undistorted":
        x1, x2 = undistorted_pixels(c1, x1), undistorted_pixels(c2, x2)
        notes["f_gt"] = f"{source} (undistorted pixels)"
    elif distorted_cams:
        F_gt = None
        notes["f_gt"] = ("none: the cameras have distortion and no fundamental matrix exists for their raw pixels "
                         "(no Zhang F-distance; pose via K from E = K2^T F K1 on raw pixels); pass --pixels "
                         "undistorted if the estimate is for undistorted pixels")
    else:
        notes["f_gt"] = f"{source} (pinhole cameras: raw = undistorted pixels)"
    return PairTruth(x1, x2, F_gt, c1.K, c2.K, rel.R, rel.t, (c1.width, c1.height), (c2.width, c2.height), pixels,
                     notes)


def score_pair(F, truth: PairTruth, *, inliers=None, labels=None, zhang_if_failed: bool = True) -> dict:
    """Result groups of F against ``truth``: ``fundamental`` (Sampson and symmetric epipolar RMS on
    the truth correspondences), ``zhang_f_distance`` (when a truth F exists and F is usable),
    ``pose_via_K``, and ``inliers`` (precision / recall of the estimator's mask against the truth
    labels, when both are given)."""
    res = {"fundamental": fundamental_metrics(F, truth.x1, truth.x2)}
    if truth.F_gt is not None and (zhang_if_failed or not res["fundamental"].failed):
        res["zhang_f_distance"] = zhang_f_distance(F, truth.F_gt, truth.size1, truth.size2)
    res["pose_via_K"] = pose_error_from_fundamental(F, truth.K1, truth.K2, truth.x1, truth.x2, truth.R, truth.t)
    if inliers is not None and labels is not None:
        res["inliers"] = inlier_precision_recall(inliers, labels)
    return res


#: The match set whose estimate is the method's own from the images (OpenCV's SIFT matches of the
#: two images): its headline metrics carry no set name, so a method that estimates from the images
#: itself (``run --command --kind fmatrix`` with ``{images}``, ``recon-eval fmatrix``) shares their
#: leaderboard columns and gates; the labelled synthetic set's carry ``synthetic.``.
IMAGES_SET = "sift"


def headline_prefix(i: str, j: str, kind: str, n_pairs: int) -> str:
    """The prefix of a match set's headline metrics: ``<set>.`` (none for :data:`IMAGES_SET`), with
    ``<i>__<j>.`` in front when the dataset has several pairs."""
    pair = "" if n_pairs == 1 else f"{i}__{j}."
    return pair if kind == IMAGES_SET else f"{pair}{kind}."


#: The headline metric names of an F (the ``metrics`` keys of every F method's run and of
#: ``recon-eval fmatrix --json``), each with the result group and field it comes from.
HEADLINE = {"sampson_rms_px": ("fundamental", "sampson_rms_px"), "pose_err_deg": ("pose_via_K", "pose_err_deg"),
            "f_distance_px": ("zhang_f_distance", "f_distance_px"), "inlier_recall": ("inliers", "recall"),
            "inlier_precision": ("inliers", "precision")}


def headline(res: dict, prefix: str = "") -> dict:
    """The headline metrics of an F's result groups (``score_pair``'s, or a run's groups of one
    match set), named by :data:`HEADLINE` with ``prefix`` in front: one name per number for the
    runs, the scoring command and the gates (docs/ci.md, "Metric paths")."""
    out = {}
    for name, (group, field) in HEADLINE.items():
        if group in res:
            r = res[group]
            out[prefix + name] = r[field] if isinstance(r, dict) else getattr(r, field)
    return out


def unusable_f_warning(fundamental_result, item: str) -> str | None:
    """The warning for an estimate that cannot be scored (``fundamental_metrics`` failed: a
    non-finite, zero or rank-3 F is scored as a failure, every error inf), naming ``item`` (the
    pair, and the match set); None for a usable F."""
    if not fundamental_result.failed:
        return None
    return (f"{item}: the estimated F is {fundamental_result.failure_reason}: scored as a failed estimate "
            f"(sampson_rms_px inf)")
