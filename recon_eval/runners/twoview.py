"""OpenCV two-view estimators on the cross-view putative match sets (docs/crossview.md):
``findFundamentalMat`` (7-point, 8-point, RANSAC, LMEDS and the USAC flags), ``findEssentialMat``
and ``findHomography``, each on the labelled synthetic matches and on the SIFT matches of every
pair in ``crossview/index.json``.

Match rows are raw (distorted) OpenCV pixels, read by column name
(:data:`scenegen.dataset.crossview.MATCH_COLUMNS`); the truth F/E/H of
``crossview/twoview/i/j.json`` are for undistorted pixels (x = K (X/Z, Y/Z, 1)), so points of a
distorted camera are undistorted with the truth camera model first
(:func:`scenegen.geometry.twoview.undistorted_pixels`, its exact inverse): the intrinsics are
assumed known, as the estimators' users calibrate first.

Raw output per pair and match set: ``<i>__<j>/<set>_F.txt`` (or ``_E.txt``, ``_H.txt``) and
``<set>_inliers.npy`` (bool mask the estimator returned). Scores (recon_eval.metrics.epipolar): inlier
precision/recall against the labels (label 0 = inlier), Sampson and symmetric epipolar RMS on
exact truth correspondences (truth points visible in both views by the dataset's ray-cast
states, :meth:`DatasetTruth.correspondences`), Zhang's F-distance to the
truth F, relative pose error via the truth K; for H the mean corner error (MACE) against the plane's
truth homography, on the matches whose view-i pixel sees that plane.
"""
from __future__ import annotations

from typing import Callable

import cv2
import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.epipolar import (fundamental_metrics, homography_mace, inlier_precision_recall,
                                         pose_error_from_fundamental, sampson_sq_px2, zhang_f_distance)
from recon_eval.metrics.poses import relative_pose_errors_deg
from recon_eval.runners.common import RunOutput, crossview_pairs, out_path
from recon_eval.tasks.fmatrix_pair import headline, headline_prefix, unusable_f_warning
from scenegen.geometry.twoview import undistorted_pixels

#: RANSAC-family thresholds, px. FM_RANSAC thresholds the larger point-to-epipolar-line distance
#: in either image, evaluated on a noisy 7-point model: OpenCV's default (3 px) is used, as a
#: user who does not tune it gets. USAC methods threshold the Sampson distance of a locally
#: optimised model: 1.0 px = OpenCV's USAC test value.
THRESH_PX = {"ransac": 3.0, "lmeds": 3.0}
USAC_THRESH_PX = 1.0
CONFIDENCE = 0.999
MAX_ITERS = 10000
#: Truth correspondences sampled per pair for the Sampson RMS (seeded, dataset truth).
TRUTH_POINTS = 20000
#: Seed of the 7-point method's sample.
SEVEN_POINT_SEED = 7
#: Note of a pair skipped by the F and E runners: its two views share one camera centre.
ZERO_BASELINE_NOTE = "skipped: zero baseline (one camera centre), no epipolar geometry to estimate"
#: Minimum number of matches on a plane for a homography to be attempted.
MIN_PLANE_MATCHES = 12


def _flag(name: str) -> int:
    return {"7point": cv2.FM_7POINT, "8point": cv2.FM_8POINT, "ransac": cv2.FM_RANSAC, "lmeds": cv2.FM_LMEDS,
            "usac_default": cv2.USAC_DEFAULT, "usac_parallel": cv2.USAC_PARALLEL, "usac_fm_8pts": cv2.USAC_FM_8PTS,
            "usac_fast": cv2.USAC_FAST, "usac_accurate": cv2.USAC_ACCURATE, "usac_prosac": cv2.USAC_PROSAC,
            "usac_magsac": cv2.USAC_MAGSAC}[name]


def _thresh(name: str) -> float:
    return USAC_THRESH_PX if name.startswith("usac") else THRESH_PX.get(name, 1.0)


def fit_opencv_f(flag: str, x1, x2):
    """cv2.findFundamentalMat with the flag's method and this module's thresholds: (F or None, mask or None)."""
    if flag in ("7point", "8point"):
        F, mask = cv2.findFundamentalMat(x1, x2, _flag(flag))
    else:
        F, mask = cv2.findFundamentalMat(x1, x2, _flag(flag), _thresh(flag), CONFIDENCE, MAX_ITERS)
    return F, mask


def fundamental(ds, out_dir, options, *, transform_F: Callable[[np.ndarray], np.ndarray] | None = None,
                fit: Callable | None = None) -> RunOutput:
    """cv2.findFundamentalMat with ``options["flag"]`` on every match set of every pair (module
    docstring). ``transform_F`` maps the estimate before it is written (only
    :mod:`recon_eval.runners.faults` sets it). ``fit(i, j, kind, x1, x2) -> (F or None, mask or
    None)`` replaces OpenCV (an external estimator, :mod:`recon_eval.runners.external`; the survey's
    estimators, :mod:`recon_eval.runners.fsurvey`): it gets the matches the flag feeds (every match of
    the set, undistorted; with flag 7point / 8point the labelled inliers as OpenCV's own), F may
    stack several solutions (3k, 3) as OpenCV's 7-point does; a None mask claims every match given an
    inlier."""
    flag = options.get("flag", "external")
    pairs = crossview_pairs(ds)
    out = RunOutput()
    for i, j in pairs:
        (ci, pi), (cj, pj) = ds.camera(i), ds.camera(j)
        tv = ds.read(ds.dataset.crossview.twoview, i, j)
        if tv.F is None:  # one camera centre (crossview.md): F and E do not exist
            out.notes[f"{i}__{j}"] = ZERO_BASELINE_NOTE
            continue
        F_gt = tv.F
        rel = pj @ pi.inverse()
        t1, t2 = ds.correspondences(i, j, max_points=TRUTH_POINTS)
        t1, t2 = undistorted_pixels(ci, t1), undistorted_pixels(cj, t2)
        for ms in ds.match_sets(i, j):
            kind, n = ms.kind, len(ms)
            x1, x2 = undistorted_pixels(ci, ms.points_i), undistorted_pixels(cj, ms.points_j)
            true_inl = ms.inliers
            use = np.ones(n, bool)
            if flag in ("7point", "8point"):  # no robust loop: fed the labelled inliers only
                use = true_inl.copy()
            if flag == "7point":  # 7 labelled inliers drawn uniformly (seeded)
                pick = np.random.default_rng(SEVEN_POINT_SEED).choice(np.flatnonzero(use), 7, replace=False)
                use = np.zeros(n, bool)
                use[pick] = True
            F, mask = fit_opencv_f(flag, x1[use], x2[use]) if fit is None else fit(i, j, kind, x1[use], x2[use])
            if flag == "7point" and F is not None and len(F) > 3:  # up to 3 solutions: keep the one with
                sols = np.asarray(F).reshape(-1, 3, 3)  # the lowest median Sampson on the labelled inliers
                F = min(sols, key=lambda G: float(np.median(sampson_sq_px2(G, x1[true_inl], x2[true_inl]))))
            key = f"{i}__{j}.{kind}"
            if F is None or np.asarray(F).shape != (3, 3):
                out.warnings.append(f"{i}__{j} ({kind} matches): the estimator returned no F: scored as a failed "
                                    f"estimate (sampson_rms_px inf)")
                F, inl = np.full((3, 3), np.nan), np.zeros(n, bool)
                returned = False
            else:
                F = np.asarray(F, np.float64)
                if transform_F is not None:
                    F = transform_F(F)
                returned = True
                inl = np.zeros(n, bool)
                inl[np.flatnonzero(use)] = np.ones(int(use.sum()), bool) if mask is None else mask.ravel() != 0
            fpath = out_path(out_dir, f"{i}__{j}/{kind}_F.txt")
            np.savetxt(fpath, F)
            np.save(out_path(out_dir, f"{i}__{j}/{kind}_inliers.npy"), inl)
            out.raw_files += [f"{i}__{j}/{kind}_F.txt", f"{i}__{j}/{kind}_inliers.npy"]
            F = np.loadtxt(fpath)  # score what was written
            fm = fundamental_metrics(F, t1, t2)
            if returned and (w := unusable_f_warning(fm, f"{i}__{j} ({kind} matches)")):
                out.warnings.append(w)
            ir = inlier_precision_recall(inl, true_inl)
            zd = zhang_f_distance(F, F_gt, (ci.width, ci.height), (cj.width, cj.height)) if not fm.failed else None
            pe = pose_error_from_fundamental(F, ci.K, cj.K, t1, t2, rel.R, rel.t)
            out.results[f"{key}.fundamental"] = fm
            out.results[f"{key}.inliers"] = ir
            if zd is not None:
                out.results[f"{key}.zhang_f_distance"] = zd
            out.results[f"{key}.pose_via_K"] = pe
            groups = {"fundamental": fm, "pose_via_K": pe, "inliers": ir}
            if zd is not None:
                groups["zhang_f_distance"] = zd
            out.metrics.update(headline(groups, headline_prefix(i, j, kind, len(pairs))))
            out.notes[f"{key}.matches"] = {"n": int(n), "used": int(use.sum()),
                                           "true_inliers": int(true_inl.sum()),
                                           "threshold_px": _thresh(flag) if flag in THRESH_PX
                                           or flag.startswith("usac") else None}
    if not out.raw_files:
        raise NotApplicable(f"{ds.root}: the cross-view pairs have no match sets (or only zero-baseline pairs)")
    return out


def essential(ds, out_dir, options) -> RunOutput:
    flag = options["flag"]
    meth = {"ransac": cv2.RANSAC, "lmeds": cv2.LMEDS, "usac_magsac": cv2.USAC_MAGSAC}[flag]
    pairs = crossview_pairs(ds)
    out = RunOutput()
    for i, j in pairs:
        (ci, pi), (cj, pj) = ds.camera(i), ds.camera(j)
        rel = pj @ pi.inverse()
        if ds.read(ds.dataset.crossview.twoview, i, j).E is None:
            out.notes[f"{i}__{j}"] = ZERO_BASELINE_NOTE
            continue
        for ms in ds.match_sets(i, j):
            kind, n = ms.kind, len(ms)
            # normalised coordinates through each truth camera (the two intrinsics may differ)
            n1 = ci.unproject(ms.points_i)[:, :2]
            n2 = cj.unproject(ms.points_j)[:, :2]
            f = 0.5 * (ci.K[0, 0] + cj.K[0, 0])
            E, mask = cv2.findEssentialMat(n1, n2, np.eye(3), meth, CONFIDENCE, _thresh(flag) / f)
            key = f"{i}__{j}.{kind}"
            if E is None or E.shape[0] < 3:
                E, inl, R, t = np.full((3, 3), np.nan), np.zeros(n, bool), np.full((3, 3), np.nan), np.full(3, np.nan)
            else:
                E = E[:3]
                inl = mask.ravel() != 0
                _, R, t, _ = cv2.recoverPose(E, n1[inl], n2[inl], np.eye(3))
            np.savetxt(out_path(out_dir, f"{i}__{j}/{kind}_E.txt"), E)
            np.save(out_path(out_dir, f"{i}__{j}/{kind}_inliers.npy"), inl)
            out.raw_files += [f"{i}__{j}/{kind}_E.txt", f"{i}__{j}/{kind}_inliers.npy"]
            if np.all(np.isfinite(R)):
                eR, et, ep = (float(a[0]) for a in relative_pose_errors_deg(R[None], np.reshape(t, (1, 3)),
                                                                         rel.R[None], rel.t[None]))
            else:
                eR = et = ep = float("inf")
            ir = inlier_precision_recall(inl, ms.inliers)
            out.results[f"{key}.inliers"] = ir
            out.results[f"{key}.relative_pose"] = {"rot_err_deg": eR, "trans_dir_err_deg": et, "pose_err_deg": ep}
            pre = headline_prefix(i, j, kind, len(pairs))
            out.metrics.update({pre + "pose_err_deg": ep, pre + "rot_err_deg": eR, pre + "inlier_recall": ir.recall,
                                pre + "inlier_precision": ir.precision})
    if not out.raw_files:
        raise NotApplicable(f"{ds.root}: the cross-view pairs have no match sets (or only zero-baseline pairs)")
    return out


def homography(ds, out_dir, options) -> RunOutput:
    flag = options["flag"]
    meth = {"ransac": cv2.RANSAC, "usac_magsac": cv2.USAC_MAGSAC}[flag]
    pairs = crossview_pairs(ds)
    out = RunOutput()
    for i, j in pairs:
        ci, _ = ds.camera(i)
        cj, _ = ds.camera(j)
        planes = ds.read(ds.dataset.crossview.twoview, i, j).homographies
        if not planes:
            continue
        obj_i = ds.object_ids(i)
        for ms in ds.match_sets(i, j):
            kind = ms.kind
            ui = np.clip(np.rint(ms.column("u_i")).astype(int), 0, ci.width - 1)
            vi = np.clip(np.rint(ms.column("v_i")).astype(int), 0, ci.height - 1)
            oid = obj_i[vi, ui]
            for plane, H_gt in planes.items():
                on = oid == ds.object_id(plane)
                if on.sum() < MIN_PLANE_MATCHES:
                    continue
                x1, x2 = undistorted_pixels(ci, ms.points_i[on]), undistorted_pixels(cj, ms.points_j[on])
                H, mask = cv2.findHomography(x1, x2, meth, _thresh(flag), maxIters=MAX_ITERS, confidence=CONFIDENCE)
                H = np.full((3, 3), np.nan) if H is None else H
                key = f"{i}__{j}.{kind}.{plane}"
                hp = out_path(out_dir, f"{i}__{j}/{kind}_{plane}_H.txt")
                np.savetxt(hp, H)
                out.raw_files.append(f"{i}__{j}/{kind}_{plane}_H.txt")
                r = homography_mace(np.loadtxt(hp), H_gt, ci.width, ci.height)
                out.results[f"{key}.homography"] = r
                pre = headline_prefix(i, j, kind, len(pairs)) + f"{plane}."
                out.metrics[pre + "mace_px"] = r.mace_px
                out.notes[f"{key}.matches_on_plane"] = int(on.sum())
    if not out.raw_files:
        raise NotApplicable(f"{ds.root}: no planar object with enough matches in any cross-view pair")
    return out
