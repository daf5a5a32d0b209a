"""One camera pose (PnP output) from .json, .npy or text.

* JSON: ``{"R": 3x3, "t": 3}`` (our cameras.json form), ``{"cam_from_world": {"R", "t"}}``,
  ``{"world_from_cam": {"R", "t"}}`` (the key states the convention), or a 3x4 / 4x4 matrix;
* .npy or text (whitespace/commas, '#' comments): 12 numbers (3x4 ``[R | t]``, row-major) or 16
  (4x4, last row 0 0 0 1).

A bare matrix is read in ``convention`` (default ``cam_from_world``, OpenCV ``solvePnP``'s
``x_cam = R x_world + t``). Non-finite values are kept: a failed estimate is scored as a failure
(:func:`recon_eval.metrics.pnp.pnp_errors`), not refused.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.npy import read_npy
from recon_eval.readers.text import json_document, read_text
from scenegen.geometry.rotation import is_rotation

CONVENTIONS = ("cam_from_world", "world_from_cam")


def _from_matrix(M: np.ndarray, p: Path) -> tuple[np.ndarray, np.ndarray]:
    if M.size == 16:
        M = M.reshape(4, 4)
        if np.all(np.isfinite(M[3])) and not np.allclose(M[3], [0, 0, 0, 1]):
            raise InputError(f"{p}: a 4x4 pose must end with the row 0 0 0 1, got {M[3].tolist()}")
        M = M[:3]
    elif M.size == 12:
        M = M.reshape(3, 4)
    else:
        raise InputError(f"{p}: expected a 3x4 or 4x4 pose matrix (12 or 16 numbers), got {M.size}")
    return M[:, :3].copy(), M[:, 3].copy()


def read_pose(path, convention: str = "cam_from_world") -> tuple[np.ndarray, np.ndarray]:
    """(R_cam_from_world (3, 3), t_cam_from_world (3,)) float64; see the module docstring."""
    if convention not in CONVENTIONS:
        raise InputError(f"pose convention must be one of {CONVENTIONS}, got {convention!r}")
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a camera pose: .json, .npy or .txt)")
    if p.suffix.lower() == ".npy":
        R, t = _from_matrix(read_npy(p), p)
    elif p.suffix.lower() == ".json":
        obj = json_document(read_text(p, "a camera pose as JSON"), p, "a camera pose")
        if isinstance(obj, dict):
            for key in CONVENTIONS:
                if key in obj:
                    convention, obj = key, obj[key]
                    break
        try:
            if isinstance(obj, dict):
                if "R" not in obj or "t" not in obj:
                    raise InputError(f"{p}: expected fields R (3x3) and t (3), got keys {sorted(obj)}")
                R = np.asarray(obj["R"], dtype=np.float64)
                t = np.asarray(obj["t"], dtype=np.float64).reshape(-1)
                if R.shape != (3, 3) or t.shape != (3,):
                    raise InputError(f"{p}: R must be 3x3 and t 3 numbers, got {R.shape} and {t.shape}")
            else:
                R, t = _from_matrix(np.asarray(obj, dtype=np.float64), p)
        except (TypeError, ValueError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"{p}: R, t: expected numbers ({exc})") from None
    else:
        lines = [ln.split("#", 1)[0] for ln in read_text(p, "a camera pose as text").splitlines()]
        try:
            M = np.array([float(v) for v in " ".join(lines).replace(",", " ").split()])
        except ValueError:
            raise InputError(f"{p}: expected 12 or 16 numbers") from None
        R, t = _from_matrix(M, p)
    if np.all(np.isfinite(R)) and not is_rotation(R):  # NaN: a failed estimate, scored as a failure
        err = float(np.abs(R @ R.T - np.eye(3)).max())
        raise InputError(f"{p}: R is not a rotation (|R R^T - I| = {err:.2g}, det {np.linalg.det(R):.6g}; "
                         "expected orthonormal with det +1)")
    if convention == "world_from_cam":
        R = R.T
        t = -R @ t
    return R, t
