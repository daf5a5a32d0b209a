"""Shape from texture on a dataset's views of a textured plane, scored by the plane's orientation
(:func:`recon_eval.metrics.normals.plane_orientation_metrics`): every view whose truth is a single
plane (one object, one normal in the camera frame).

* ``structure_tensor``: foreshortening of an isotropic texture (Witkin 1981; the second-moment
  form of Garding 1992, under the orthographic approximation): an isotropic texture's gradients
  have covariance c I on the plane, and a plane at slant s compresses the image by cos s along the
  tilt direction t, so the image's gradient covariance is c R diag(1, 1 / cos^2 s) R^T. The method
  averages the local structure tensors (gradients of the grey linear image by central differences,
  Gaussian window sigma ``window_px``, each normalised by its trace so near and far texture weigh
  alike) over the plane's pixels: cos s = sqrt(lambda_2 / lambda_1), t = the eigenvector of
  lambda_1. The sign of t (orthography cannot tell) comes from perspective: texture gets finer with
  distance, so t points where log(local gradient energy) grows (its least-squares slope over the
  image). Normal in the camera frame: (sin s t_u, sin s t_v, -cos s).

Raw output: ``texture/normals.txt`` (one row per view: view name, n_x n_y n_z, OpenCV camera
frame), read back and scored per view; the run's headline numbers are means over the views.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.normals import plane_orientation_metrics
from recon_eval.readers.rows import read_rows
from recon_eval.runners.common import RunOutput, out_path
from scenegen.dataset import Dataset
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.color import linear_from_srgb


def plane_normal_from_texture(grey: np.ndarray, mask: np.ndarray, window_px: float) -> np.ndarray:
    """(3,) unit normal (OpenCV camera frame, toward the camera) of the textured plane seen in the
    (H, W) grey image over ``mask`` (module docstring)."""
    gv, gu = np.gradient(grey)
    J = np.stack([gaussian_filter(a, window_px) for a in (gu * gu, gu * gv, gv * gv)])  # (3, H, W)
    tr = J[0] + J[2]
    m = mask & (tr > 0)
    m[: int(3 * window_px)], m[-int(3 * window_px):] = False, False  # windows reaching past the image
    m[:, : int(3 * window_px)], m[:, -int(3 * window_px):] = False, False
    if m.sum() < 10:
        raise InputError("shape from texture: fewer than 10 textured pixels inside the image")
    Jn = J[:, m] / tr[m]
    M = np.array([[Jn[0].mean(), Jn[1].mean()], [Jn[1].mean(), Jn[2].mean()]])
    lam, vec = np.linalg.eigh(M)  # ascending
    cos_s = float(np.sqrt(max(lam[0], 0.0) / lam[1]))
    t = vec[:, 1]
    v, u = np.nonzero(m)
    A = np.c_[u - u.mean(), v - v.mean()]
    slope = np.linalg.lstsq(A, np.log(tr[m]), rcond=None)[0]
    if t @ slope < 0:
        t = -t
    sin_s = float(np.sqrt(max(0.0, 1.0 - cos_s * cos_s)))
    return np.array([sin_s * t[0], sin_s * t[1], -cos_s])


def structure_tensor(ds, out_dir, options) -> RunOutput:
    window = float(options.get("window_px", 4.0))
    try:
        d = Dataset(ds.root)
        views, normals, truths = [], [], []
        for v in d.views:
            t = d.truth(v)
            ids = np.unique(t[TruthKind.OBJECT_ID][t[TruthKind.VALID]])
            n = t[TruthKind.NORMALS_CAM][t[TruthKind.VALID]].astype(np.float64)
            if len(ids) != 1 or len(n) < 100 or np.abs(n - n[0]).max() > 1e-3:
                continue  # not one plane
            img = np.asarray(d.image(v))
            grey = linear_from_srgb(img / float(np.iinfo(img.dtype).max))
            grey = grey.mean(axis=-1) if grey.ndim == 3 else grey
            views.append(v)
            normals.append(plane_normal_from_texture(grey, t[TruthKind.VALID], window))
            truths.append(n.mean(axis=0))
    except DatasetError as exc:
        raise InputError(str(exc)) from None
    if not views:
        raise NotApplicable(f"{ds.root}: no view of a single textured plane")
    rel = "texture/normals.txt"
    lines = ["# view n_x n_y n_z (OpenCV camera frame, toward the camera)"]
    lines += [f"{v} {n[0]:.17g} {n[1]:.17g} {n[2]:.17g}" for v, n in zip(views, normals)]
    out_path(out_dir, rel).write_text("\n".join(lines) + "\n")
    rows = read_rows(Path(out_dir) / rel, "view n_x n_y n_z", (3,), n_labels=1)
    results = {row.labels[0]: plane_orientation_metrics(g, row.values) for row, g in zip(rows, truths)}
    r = list(results.values())
    metrics = {"mean_angle_err_deg": float(np.mean([x.angle_err_deg for x in r])),
               "max_angle_err_deg": float(np.max([x.angle_err_deg for x in r])),
               "mean_angle_err_folded_deg": float(np.mean([x.angle_err_folded_deg for x in r])),
               "mean_slant_err_deg": float(np.mean([x.slant_err_deg for x in r])),
               "mean_tilt_err_deg": float(np.nanmean([x.tilt_err_deg for x in r]))}
    return RunOutput(results, metrics, [rel], {"views": views, "window_px": window})
