"""PnP (absolute pose) metrics: rotation angle (atan2 form), translation error absolute and
relative, camera-centre error, reprojection RMS (metrics.md, "Calibration and PnP").
Poses are cam_from_world (R (3, 3), t (3,) metres)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.metrics.calibration import ReprojectionResult, reprojection_rms
from scenegen.geometry.rotation import rotation_error_rad


@dataclass(frozen=True)
class PnpResult:
    rot_err_deg: float  # angle of R_est^T R_gt (atan2 form); inf if the estimate is non-finite
    trans_abs_err_m: float  # |t_est - t_gt|
    trans_rel_err: float  # |t_est - t_gt| / |t_gt|
    center_err_m: float  # |c_est - c_gt| with c = -R^T t
    reprojection: ReprojectionResult | None  # on the given points, through the truth camera model
    failed: bool


def pnp_errors(R_est, t_est, R_gt, t_gt, *, cam=None, points_world=None, pixels=None) -> PnpResult:
    """Errors of an estimated pose against the truth; reprojection RMS of ``points_world`` (N, 3)
    against ``pixels`` (N, 2) through ``cam`` at the *estimated* pose when all three are given."""
    Re = np.asarray(R_est, dtype=np.float64)
    te = np.asarray(t_est, dtype=np.float64).reshape(-1)
    Rg = as_float_array(R_gt, "R_gt", (3, 3))
    tg = as_float_array(t_gt, "t_gt", (3,))
    if Re.shape != (3, 3) or te.shape != (3,) or not (np.all(np.isfinite(Re)) and np.all(np.isfinite(te))):
        return PnpResult(np.inf, np.inf, np.inf, np.inf, None, True)
    dt = float(np.linalg.norm(te - tg))
    ng = float(np.linalg.norm(tg))
    rep = None
    if cam is not None and points_world is not None and pixels is not None:
        rep = reprojection_rms(cam, Re, te, points_world, pixels)
    return PnpResult(
        float(np.degrees(rotation_error_rad(Re, Rg))), dt, dt / ng if ng > 0 else float("nan"),
        float(np.linalg.norm(-Re.T @ te + Rg.T @ tg)), rep, False,
    )
