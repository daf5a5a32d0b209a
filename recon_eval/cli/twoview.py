"""``recon-eval fmatrix`` and ``recon-eval homography``: two-view estimates against exact truth
(docs/metrics.md, "Fundamental matrices and homographies")."""
from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

from recon_eval.cli.common import image_size
from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.epipolar import (fundamental_degeneracy, homography_degeneracy, homography_mace,
                                         homography_summary, sampson_sq_px2)
from recon_eval.readers.matrix import read_matrix3
from recon_eval.readers.npy import read_mask, read_npy
from recon_eval.readers.registry import read_image
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure
from recon_eval.tasks.fmatrix_pair import (IMAGES_SET, PIXELS, PairTruth, headline, headline_prefix, pair_truth,
                                           score_pair, unusable_f_warning)
from scenegen.dataset.layout import MATCH_KINDS


# --- fundamental matrix -----------------------------------------------------------------------
def fmatrix_arguments(p) -> None:
    p.add_argument("f_est", help="estimated F (.txt/.npy/.json)")
    p.add_argument("--matches", help="truth correspondences .npy (N, 4): x1 y1 x2 y2, OpenCV pixels")
    p.add_argument("--f-gt", help="truth F for Zhang's F-distance")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), help="image size for Zhang's F-distance")
    p.add_argument("--dataset", help="dataset folder: truth F, correspondences, K, size and images of --views")
    p.add_argument("--views", nargs=2, metavar=("VIEW1", "VIEW2"),
                   help="the two dataset views (F maps 1 -> 2); their truth correspondences need the pair in the "
                        "spec's crossview.pairs")
    p.add_argument("--pixels", choices=PIXELS, default="undistorted",
                   help="dataset truth: the pixels F (and --matches rows) are for: undistorted (default; F exists only there: the "
                        "dataset's truth F, Zhang distance and pose via K) or distorted (the raw pixels of the "
                        "stored images; no truth F for cameras with distortion). Same for pinhole cameras")
    p.add_argument("--match-set", choices=list(MATCH_KINDS),
                   help="dataset truth: the labelled putative matches of the pair (crossview/matches) whose rows "
                        "--inliers labels")
    p.add_argument("--inliers", metavar="MASK",
                   help="the estimator's inlier mask (.npy bool / 0-1, or text), one value per row of --match-set "
                        "or of --labels: inlier precision and recall")
    p.add_argument("--labels", metavar="LABELS",
                   help="without a dataset: the truth inlier labels (.npy bool / 0-1) of the rows --inliers labels")
    p.add_argument("--max-matches", type=int, default=20000, help="dataset correspondences sampled (seeded)")
    p.add_argument("--images", nargs=2, metavar=("IMG1", "IMG2"), help="images for the HTML epipolar-line figure")


def _dataset_labels(ds, v1, v2, kind):
    for ms in ds.match_sets(v1, v2):
        if ms.kind == kind:
            return ms.inliers
    raise InputError(f"{ds.root}: views {v1!r} -> {v2!r} have no {kind!r} match set (crossview/matches)")


def score_fmatrix(a):
    F = read_matrix3(a.f_est, key="F")
    inputs = {"f_est": a.f_est, "matches": a.matches, "f_gt": a.f_gt, "dataset": a.dataset, "views": a.views}
    labels = images = None
    if a.size:
        image_size(a.size)  # two positive numbers (InputError otherwise)
    if a.dataset:
        if not a.views:
            raise InputError("--dataset needs --views VIEW1 VIEW2")
        if a.labels:
            raise InputError("--labels is for a truth without a dataset; with --dataset give --match-set KIND")
        ds = read_dataset(a.dataset)
        v1, v2 = a.views
        truth = pair_truth(ds, v1, v2, pixels=a.pixels, max_points=a.max_matches, correspondences=not a.matches)
        if a.matches:  # the user's own truth correspondences replace the dataset's
            m = read_npy(a.matches, (None, 4))
            truth = replace(truth, x1=m[:, :2], x2=m[:, 2:], notes={**truth.notes, "correspondences": a.matches})
        if a.f_gt:
            truth = replace(truth, F_gt=read_matrix3(a.f_gt, key="F"), notes={**truth.notes, "f_gt": a.f_gt})
        if a.size:
            truth = replace(truth, size1=tuple(a.size), size2=tuple(a.size))
        if a.match_set:
            labels = _dataset_labels(ds, v1, v2, a.match_set)
        inputs.update(truth.notes, matches=truth.notes["correspondences"], match_set=a.match_set)
        images = (ds.image(v1), ds.image(v2))
    else:
        if a.match_set:
            raise InputError("--match-set needs --dataset DIR --views V1 V2")
        if not a.matches:
            raise InputError("fmatrix needs --matches M.npy or --dataset DIR --views V1 V2")
        m = read_npy(a.matches, (None, 4))
        F_gt = read_matrix3(a.f_gt, key="F") if a.f_gt else None
        if F_gt is not None and not a.size:
            raise InputError("--f-gt needs --size W H for Zhang's F-distance")
        size = tuple(a.size) if a.size else None
        eye = np.full((3, 3), np.nan)
        truth = PairTruth(m[:, :2], m[:, 2:], F_gt, eye, eye, eye, np.full(3, np.nan), size, size, "as given", {})
        labels = read_mask(a.labels, len(m)) if a.labels else None  # one label per row of --matches
    inliers = None
    if a.inliers:
        if labels is None:
            raise InputError("--inliers needs the truth labels of its rows: --match-set KIND (dataset) or --labels")
        inliers = read_mask(a.inliers, len(labels))
    elif a.labels:
        raise InputError("--labels needs --inliers MASK (the estimator's mask over the same rows)")
    res = score_pair(F, truth, inliers=inliers, labels=labels)
    item = f"{a.views[0]}__{a.views[1]}" if a.dataset else a.f_est
    if w := unusable_f_warning(res["fundamental"], item):  # a NaN F is scored inf: say so
        print(f"recon-eval: warning: {a.method or a.f_est}: {w}", file=sys.stderr)
    if not a.dataset:
        del res["pose_via_K"]  # no cameras without a dataset
    if a.images:
        images = tuple(read_image(p) for p in a.images)
    inputs["size"] = truth.size1
    x1, x2, F_gt = truth.x1, truth.x2, truth.F_gt

    def figures():
        figs = []
        if fundamental_degeneracy(F) is None:
            with np.errstate(invalid="ignore", divide="ignore"):
                s = np.sqrt(sampson_sq_px2(F, x1, x2))
            figs.append(Figure("Cumulative Sampson error", plots.cumulative_figure(
                {"sqrt(Sampson)": np.where(np.isfinite(s), s, np.inf)}, xlabel="Sampson error (px)",
                title="on the truth correspondences", thresholds=(1.0,))))
        if images is not None:
            figs.append(Figure("Epipolar lines", plots.epipolar_figure(images[0], images[1], F, x1, x2, F_gt=F_gt),
                               "16 truth correspondences (seeded)"))
        return figs

    return inputs, res, figures


def fmatrix_headline(a, res) -> dict:
    """``metrics`` of ``fmatrix --json``: the names an F method's run gives the same numbers
    (:func:`recon_eval.tasks.fmatrix_pair.headline`): ``sampson_rms_px``, ``pose_err_deg``,
    ``f_distance_px`` (and ``inlier_recall``, ``inlier_precision``); with ``--match-set synthetic``
    the estimate is of that set, named ``synthetic.`` as the runs name it."""
    return headline(res, headline_prefix(*(a.views or ("", "")), a.match_set or IMAGES_SET, 1))


# --- homography -------------------------------------------------------------------------------
def homography_arguments(p) -> None:
    p.add_argument("h_est", help="estimated H (.txt/.npy/.json)")
    p.add_argument("h_gt", help="truth H (.txt/.npy/.json)")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), required=True,
                   help="image size in pixels (the corners the homography is measured at)")


def score_homography(a):
    W, H = image_size(a.size)
    H_gt = read_matrix3(a.h_gt, key="H")
    if (why := homography_degeneracy(H_gt)) is not None:
        raise InputError(f"{a.h_gt}: the truth H is degenerate ({why})")
    r = homography_mace(read_matrix3(a.h_est, key="H"), H_gt, W, H)
    return ({"h_est": a.h_est, "h_gt": a.h_gt, "size": a.size},
            {"homography": r, "summary": homography_summary([r.mace_px])}, no_figures)


COMMANDS = {"fmatrix": scored(fmatrix_arguments, score_fmatrix, fmatrix_headline),
            "homography": scored(homography_arguments, score_homography)}
