"""Object recognition by invariant features (the course's second method), with OpenCV: SIFT
keypoints of the reference renders of each model (BOP's ``train/`` split: images of the model
alone with their ``cam_from_model`` and depth) are lifted to model coordinates through the
reference depth; the test image's SIFT descriptors are matched to them (Lowe's ratio test,
:data:`RATIO`, against the nearest descriptor of another model point: one point seen in several
reference views gives near-identical descriptors, which a plain second-nearest test would reject), and ``cv2.solvePnPRansac`` (EPnP minimal sets, :data:`RANSAC_PX` px) gives the
pose, refined with ``cv2.solvePnPRefineLM`` on the inliers. Several instances: the inliers are
removed and RANSAC runs again, up to the target's ``inst_count``. Score: the inlier count.

Input: the dataset's BOP export with a ``train/`` (or ``train_pbr/``) split of reference renders;
output ``poses_bop19.csv``, scored with BOP19 AR.
"""
from __future__ import annotations

import time
from pathlib import Path

import cv2
import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.readers.bop import read_bop_dataset
from recon_eval.runners.objects_common import bop_export, score_bop_run

RATIO = 0.8  # Lowe's ratio test
KNN = 40  # neighbours searched for the ratio test's second point (more than the views of one point)
SAME_POINT = 0.05  # fraction of the diameter within which two reference points are one
RANSAC_PX = 4.0
RANSAC_ITERATIONS = 2000
MIN_INLIERS = 8
SEED = 0


def _grey(split: Path, scene_id: int, im_id: int) -> np.ndarray:
    for ext in ("png", "jpg"):
        p = split / f"{scene_id:06d}" / "rgb" / f"{im_id:06d}.{ext}"
        if p.is_file():
            img = cv2.imread(str(p), cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise InputError(f"{p}: not a readable image")
            return img
    raise NotApplicable(f"{split / f'{scene_id:06d}' / 'rgb'}: no image {im_id:06d}.png (the features runner needs RGB)")


def reference_features(ref, sift) -> dict:
    """obj_id -> (descriptors (N, 128) float32, model points (N, 3) mm) of every reference view."""
    out: dict = {}
    for (scene_id, im_id), gts in sorted(ref.gts.items()):
        view = ref.views[(scene_id, im_id)]
        seen = [g for g in gts if g.visib_fract > 0]
        if len(seen) != 1 or view.depth is None:
            continue  # a reference render shows one model, with depth
        g = seen[0]
        kps, desc = sift.detectAndCompute(_grey(ref.split, scene_id, im_id), None)
        if desc is None:
            continue
        uv = np.array([k.pt for k in kps])
        ui, vi = np.round(uv[:, 0]).astype(int), np.round(uv[:, 1]).astype(int)
        z = view.depth[np.clip(vi, 0, view.height - 1), np.clip(ui, 0, view.width - 1)]
        ok = z > 0
        K = view.K
        cam = np.column_stack([(uv[ok, 0] - K[0, 2]) / K[0, 0] * z[ok], (uv[ok, 1] - K[1, 2]) / K[1, 1] * z[ok], z[ok]])
        pts = (cam - g.t) @ g.R  # model_from_cam
        d, p = out.get(g.obj_id, (np.zeros((0, 128), np.float32), np.zeros((0, 3))))
        out[g.obj_id] = (np.vstack([d, desc[ok]]), np.vstack([p, pts]))
    return out


def _distinct(ms, points: np.ndarray, same: float) -> bool:
    """Lowe's test of the nearest match ``ms[0]`` against the nearest match to another point
    (farther than ``same`` mm); fails when there is no other point among the neighbours."""
    if not ms:
        return False
    p0 = points[ms[0].trainIdx]
    for m in ms[1:]:
        if np.linalg.norm(points[m.trainIdx] - p0) > same:
            return ms[0].distance < RATIO * m.distance
    return False


def _poses(x, X, K, n: int):
    """Up to ``n`` (R, t, inliers) by sequential RANSAC on the 2D-3D pairs."""
    out, keep = [], np.arange(len(x))
    while len(out) < n and len(keep) >= MIN_INLIERS:
        ok, rvec, tvec, inl = cv2.solvePnPRansac(X[keep], x[keep], K, None, iterationsCount=RANSAC_ITERATIONS,
                                                 reprojectionError=RANSAC_PX, confidence=0.999,
                                                 flags=cv2.SOLVEPNP_EPNP)
        if not ok or inl is None or len(inl) < MIN_INLIERS:
            break
        idx = keep[inl.ravel()]
        rvec, tvec = cv2.solvePnPRefineLM(X[idx], x[idx], K, None, rvec, tvec)
        if tvec[2, 0] <= 0:
            break
        out.append((cv2.Rodrigues(rvec)[0], tvec.ravel(), len(idx)))
        keep = np.setdiff1d(keep, idx)
    return out


def estimate(bop, ref) -> tuple[list, dict]:
    cv2.setRNGSeed(SEED)
    sift = cv2.SIFT_create()
    refs = reference_features(ref, sift)
    matcher = cv2.BFMatcher(cv2.NORM_L2)
    by_image: dict = {}
    for t in bop.targets:
        by_image.setdefault((t.scene_id, t.im_id), []).append(t)
    rows = []
    for (scene_id, im_id), targets in sorted(by_image.items()):
        t0 = time.perf_counter()
        kps, desc = sift.detectAndCompute(_grey(bop.split, scene_id, im_id), None)
        found = []
        for tg in targets:
            if desc is None or tg.obj_id not in refs or len(refs[tg.obj_id][0]) < 2:
                continue
            rd, rp = refs[tg.obj_id]
            same = SAME_POINT * bop.models[tg.obj_id].diameter
            pairs = [ms[0] for ms in matcher.knnMatch(desc, rd, k=KNN) if _distinct(ms, rp, same)]
            x = np.array([kps[m.queryIdx].pt for m in pairs], dtype=np.float64).reshape(-1, 2)
            X = np.array([rp[m.trainIdx] for m in pairs], dtype=np.float64).reshape(-1, 3)
            found += [(tg.obj_id, float(n), R, t) for R, t, n in _poses(x, X, bop.views[(scene_id, im_id)].K,
                                                                         tg.inst_count)]
        dt = time.perf_counter() - t0
        rows += [(scene_id, im_id, o, s, R, t, dt) for o, s, R, t in found]
    return rows, {"reference_views": len(ref.gts), "reference_split": str(ref.split),
                  "opencv_version": cv2.__version__}


def run(ds, out_dir, options: dict):
    bop = bop_export(ds)
    split = next((bop.root / s for s in ("train", "train_pbr") if (bop.root / s).is_dir()), None)
    if split is None:
        raise NotApplicable(f"{bop.root}: no train/ split of reference renders (the features runner needs them)")
    rows, notes = estimate(bop, read_bop_dataset(split, with_targets=False))
    return score_bop_run(bop, out_dir, rows, notes)
