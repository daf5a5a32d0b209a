"""Depth from zooming (Ma and Olsen, "Depth from zooming", JOSA A 7(10), 1990) on a dataset's zoom
series: views with one orientation whose centres lie on the first view's optical axis and whose
focal lengths differ (a zoom lens: focal length and entrance pupil move together; the calibration,
f_i and the pupil's travel d_i toward the scene, comes from cameras.json, as a calibrated zoom
lens gives it).

* ``radial``: SIFT keypoints of the widest view matched into each other view (OpenCV SIFT,
  brute-force L2, Lowe's ratio 0.75). A point at depth Z (from the first view's centre) and radius
  R from the axis images at r_1 = f_1 R / Z and r_i = f_i R / (Z - d_i) from the principal point,
  so with k = r_i / r_1 and m = f_i / f_1: Z = d_i (k / m) / (k / m - 1). Matches are kept when
  r_1 > ``min_radius_px`` (near the axis the ratio is noise), the two radii point the same way
  (within 2 degrees: a zoom moves points radially) and 0 < Z < 100 m; each keypoint's depth is the
  median over the views that matched it.

Raw output ``zoom/points.txt`` (rows ``u v Z``: the first view's pixel and its depth, metres), read
back and scored with the Eigen depth metrics (no alignment) at those pixels, the truth read at the
nearest pixel centre (so the metrics' coverage is 1 by construction; ``n_points`` says how sparse).
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.depth import eigen_depth_metrics
from recon_eval.readers.rows import read_rows
from recon_eval.runners.common import RunOutput, out_path
from scenegen.dataset import Dataset
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.color import to_grey8


def zoom_series(d: Dataset) -> list[tuple[str, float, float, np.ndarray]]:
    """[(view, fx, d along the axis (m), principal point (2,))] of the first zoom series, widest
    first; NotApplicable without one."""
    first = d.views[0]
    _, p0 = d.camera(first)
    c0 = p0.inverse().t
    axis = p0.R[2]  # the optical axis in the world
    out = []
    for v in d.views:
        cam, p = d.camera(v)
        c = p.inverse().t
        off = c - c0
        if np.abs(p.R - p0.R).max() > 1e-9 or np.linalg.norm(off - axis * (off @ axis)) > 1e-9:
            continue
        out.append((v, float(cam.fx), float(off @ axis), np.array([cam.cx, cam.cy])))
    if len({round(f, 9) for _, f, _, _ in out}) < 2:
        raise NotApplicable(f"{d.root}: no zoom series (views along one optical axis with different focal lengths)")
    return sorted(out, key=lambda x: x[1])


def _match(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    sift = cv2.SIFT_create()
    ka, da = sift.detectAndCompute(a, None)
    kb, db = sift.detectAndCompute(b, None)
    if da is None or db is None or len(kb) < 2:
        return np.zeros((0, 2)), np.zeros((0, 2))
    pairs = cv2.BFMatcher(cv2.NORM_L2).knnMatch(da, db, k=2)
    good = [m for m, n in (p for p in pairs if len(p) == 2) if m.distance < 0.75 * n.distance]
    return (np.array([ka[m.queryIdx].pt for m in good]).reshape(-1, 2),
            np.array([kb[m.trainIdx].pt for m in good]).reshape(-1, 2))


def depth_from_zoom(x1, x2, c1, c2, f1: float, f2: float, d_m: float, min_radius_px: float) -> np.ndarray:
    """(N,) depth (metres from view 1's centre; NaN where rejected) of matches x1 (N, 2) in view 1
    and x2 in view i (module docstring)."""
    r1v, r2v = x1 - c1, x2 - c2
    r1, r2 = np.linalg.norm(r1v, axis=1), np.linalg.norm(r2v, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cos = np.sum(r1v * r2v, axis=1) / (r1 * r2)
        q = (r2 / r1) / (f2 / f1)
        z = d_m * q / (q - 1.0)
    ok = (r1 > min_radius_px) & (cos > np.cos(np.radians(2.0))) & (z > 0) & (z < 100.0)
    return np.where(ok, z, np.nan)


def radial(ds, out_dir, options) -> RunOutput:
    min_r = float(options.get("min_radius_px", 15.0))
    try:
        d = Dataset(ds.root)
        series = zoom_series(d)
        (v1, f1, d1, c1), rest = series[0], series[1:]
        img1 = to_grey8(d.image(v1))
        per_point: dict = {}
        for v, f, dv, c in rest:
            x1, x2 = _match(img1, to_grey8(d.image(v)))
            z = depth_from_zoom(x1, x2, c1, c, f1, f, dv - d1, min_r)
            for (u, w), zz in zip(x1, z):
                if np.isfinite(zz):
                    per_point.setdefault((round(u, 3), round(w, 3)), []).append(zz)
        depth_gt = d.truth(v1)[TruthKind.DEPTH_Z].astype(np.float64)
    except DatasetError as exc:
        raise InputError(str(exc)) from None
    rel = "zoom/points.txt"
    lines = ["# u v Z: pixel of the widest view, depth (m) from its centre"]
    lines += [f"{u:.17g} {w:.17g} {np.median(zs):.17g}" for (u, w), zs in sorted(per_point.items())]
    out_path(out_dir, rel).write_text("\n".join(lines) + "\n")
    rows = read_rows(Path(out_dir) / rel, "u v Z", (3,))
    pred = np.full(depth_gt.shape, np.nan)
    for r in rows:
        u, w, z = r.values
        pred[int(round(w)), int(round(u))] = z
    depth_gt[~np.isfinite(depth_gt)] = np.nan
    res = eigen_depth_metrics([pred], [np.where(np.isfinite(pred), depth_gt, np.nan)])
    metrics = {"abs_rel": res.abs_rel, "a1": res.a1, "rmse_m": res.rmse_m, "n_points": float(len(rows))}
    notes = {"series": [v for v, _, _, _ in series], "fx": [f for _, f, _, _ in series],
             "pupil_travel_m": [dv - d1 for _, _, dv, _ in series], "min_radius_px": min_r}
    return RunOutput({"depth": res}, metrics, [rel], notes)
