"""mrcal ``projection_diff`` (dkogan/mrcal 2.5, ``mrcal/model_analysis.py``; mrcal does not install
from PyPI here), transcribed: ``sample_imager`` (``utils.py``), ``implied_Rt10__from_unprojections``
at infinity without weights (the focus-region cut ``norm2(q0 - focus_center) < focus_radius**2``,
residual ``th2 = 2 (1 - inner(R p0, v1))``, ``least_squares(..., method='dogbox', loss='huber',
f_scale=(5 deg)^2, gtol=eps)`` from ``np.random.random(3) * 1e-5``), and the default focus region
of ``projection_diff`` without uncertainties (centre ((W-1)/2, (H-1)/2), radius min(W, H)/6). The
one change: mrcal passes its analytic Jacobian (``rotate_point_r`` gradients); the transcription
lets scipy difference the residual (3-point)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from recon_eval.metrics.calibration import mrcal_projection_diff, projection_difference
from scenegen.geometry.camera import Camera
from scenegen.geometry.rotation import matrix_from_rotvec

SIZE = (640, 480)
K = np.array([[500.0, 0, 319.5], [0, 505.0, 239.5], [0, 0, 1]])
PAIRS = {
    "pinhole.pp_shift": (Camera.from_opencv(K, None, SIZE), Camera.from_opencv(K + [[0, 0, 2.0], [0, 0, -1.5], [0, 0, 0]],
                                                                               None, SIZE)),
    "opencv.dist": (Camera.from_opencv(K, [-0.2, 0.05, 0.001, -0.0005, 0.0], SIZE),
                    Camera.from_opencv(K * [[1.004], [1.0], [1]], [-0.19, 0.04, 0.0012, -0.0004, 0.002], SIZE)),
    "fisheye.vs.opencv": (Camera.from_opencv_fisheye(K, [0.02, -0.01, 0.003, 0.0], SIZE),
                          Camera.from_opencv(K, [-0.05, 0.01, 0.0, 0.0, 0.0], SIZE)),
}


def _unit_rays(cam, q):
    v = np.asarray(cam.unproject_unit(q), float)
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _mrcal_projection_diff(a, b, gridn_width=60, seed=0, tol=1e-8):
    W, H = a.width, a.height
    gridn_height = int(round(H / W * gridn_width))
    w, h = np.linspace(0, W - 1, gridn_width), np.linspace(0, H - 1, gridn_height)
    q0 = np.ascontiguousarray(np.stack(np.meshgrid(w, h), axis=-1)).reshape(-1, 2)
    p0, v1 = _unit_rays(a, q0), _unit_rays(b, q0)
    weights = np.ones(len(q0))
    i_nan_p0, i_nan_v1 = ~np.isfinite(p0), ~np.isfinite(v1)
    p0[i_nan_p0], v1[i_nan_v1] = 0.0, 0.0
    weights[np.any(i_nan_p0, axis=1) | np.any(i_nan_v1, axis=1)] = 0.0
    focus_center, focus_radius = ((W - 1.0) / 2.0, (H - 1.0) / 2.0), float(min(W, H) / 6.0)
    i = np.sum((q0 - focus_center) ** 2, axis=1) < focus_radius * focus_radius
    p0_cut, v1_cut, w_cut = p0[i], v1[i], weights[i]

    def residual(r):
        rp0 = p0_cut @ matrix_from_rotvec(r).T
        return 2.0 * (1.0 - np.sum(rp0 * v1_cut, axis=1)) * w_cut

    r = np.random.default_rng(seed).random(3) * 1e-5
    res = least_squares(residual, r, jac="3-point", method="dogbox", loss="huber",
                        f_scale=(5 * np.pi / 180.0) ** 2, gtol=np.finfo(float).eps, verbose=0, ftol=tol, xtol=tol)
    R = matrix_from_rotvec(res.x)
    q1 = np.asarray(b.project(_unit_rays(a, q0) @ R.T), float)
    difflen = np.linalg.norm(q1 - q0, axis=1)
    ok = np.isfinite(difflen)
    return difflen[ok].mean(), difflen[ok].max(), R


@pytest.mark.parametrize("name", list(PAIRS))
def test_projection_diff_equals_mrcal(name, agreement):
    a, b = PAIRS[name]
    ours = mrcal_projection_diff(a, b)
    # mrcal's fit is determined only to ~1e-5 px: its residual 2 (1 - cos th) loses half the digits
    # to cancellation and the cost (~th^4) is flat at the optimum, so its own runs from random
    # starts differ by that much (measured: the spread below; 1.4e-4 px for opencv.dist on an AMD
    # EPYC, where FMA rounds its residuals otherwise). Ours lies within that spread.
    runs = [_mrcal_projection_diff(a, b, seed=s) for s in range(6)]
    spread = max(max(abs(m1 - m2), abs(x1 - x2)) for m1, x1, _ in runs for m2, x2, _ in runs)
    d = max(max(abs(ours.mean_px - m), abs(ours.max_px - x)) for m, x, _ in runs)
    assert d <= 2 * spread + 1e-9  # and at most the documented figure (the agreement table)
    # ours (a pixel fit over the whole grid) is another number: 0.30 vs 0.35 px for the shift
    pixel_fit = projection_difference(a, b, grid_nx=60, grid_ny=45, fit_rotation=True)
    if name == "pinhole.pp_shift":
        assert abs(pixel_fit.mean_px - ours.mean_px) > 0.1 * ours.mean_px
    agreement(f"mrcal.projection_diff.{name}", "mrcal_projection_diff mean and max (px), rotation fitted in the "
              "focus region", "mrcal `projection_diff` (transcribed)", "2.5 (dkogan/mrcal c47576e)",
              f"{name}, 640x480; mrcal's own 6 random starts spread {spread:.1g} px", d)


@pytest.mark.parametrize("name", list(PAIRS))
def test_intrinsics_only_equals_mrcal(name, agreement):
    a, b = PAIRS[name]
    ours = projection_difference(a, b, grid_nx=60, grid_ny=45)
    W, H = SIZE
    q0 = np.stack(np.meshgrid(np.linspace(0, W - 1, 60), np.linspace(0, H - 1, 45)), axis=-1).reshape(-1, 2)
    ref = np.linalg.norm(np.asarray(b.project(_unit_rays(a, q0)), float) - q0, axis=1)
    d = float(np.nanmax(np.abs(ours.diff_px.ravel() - ref)))
    assert d < 1e-8
    assert abs(mrcal_projection_diff(a, b, intrinsics_only=True).mean_px - ours.mean_px) < 1e-12
    agreement(f"mrcal.intrinsics_only.{name}", "projection_diff field, intrinsics only (px)",
              "mrcal `projection_diff(intrinsics_only=True)` (transcribed)", "2.5 (dkogan/mrcal c47576e)", f"{name}, 640x480", d)
