"""Vignetting: the relative illumination ``V(u, v)`` of each pixel (1 = on-axis irradiance).

    V(u, v) = cos^4(theta(u, v)) * P(r),    P(r) = 1 + a1 r^2 + a2 r^4 + a3 r^6

* ``theta`` is the angle between the optical axis and the chief ray through the pixel centre,
  computed by the camera model itself (distortion included: ``Camera.unproject_unit``), so it is
  the natural (cos^4) falloff of the real ray (Ray, Applied Photographic Optics, sec. 10.1).
  Optional (``natural_cos4``).
* ``P(r)`` is the polynomial radial model (mechanical / optical vignetting, as in e.g. Goldman,
  "Vignette and exposure calibration", PAMI 2010, eq. 2) about ``center_px`` (default: the
  principal point), with ``r`` the distance to the centre divided by the half-diagonal of the
  image, ``0.5 * hypot(W, H)`` pixels (r = 1 at the corners when the centre is the image centre).

``V`` is clipped to >= 0 (a polynomial that goes negative means no light, not negative light).
Pixel convention: the centre of the top-left pixel is (0, 0); array element [v, u].
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, kw_only=True)
class VignettingParams:
    natural_cos4: bool = False  # multiply by cos^4 of the chief ray's angle to the optical axis
    coeffs: tuple[float, float, float] = (0.0, 0.0, 0.0)  # a1, a2, a3 of P(r) (unitless)
    center_px: tuple[float, float] | None = None  # (u, v) centre of P(r), pixels; None = (cx, cy)

    @property
    def enabled(self) -> bool:
        return self.natural_cos4 or any(c != 0.0 for c in self.coeffs)


def radial_polynomial(r: np.ndarray, coeffs) -> np.ndarray:
    """P(r) = 1 + a1 r^2 + a2 r^4 + a3 r^6 (r unitless)."""
    a1, a2, a3 = coeffs
    r2 = np.asarray(r, dtype=np.float64) ** 2
    return 1.0 + r2 * (a1 + r2 * (a2 + r2 * a3))


def cos4_map(camera) -> np.ndarray:
    """(H, W) cos^4 of the angle between each pixel centre's ray and the optical axis (>= 0)."""
    W, H = camera.width, camera.height
    u, v = np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64))
    d = camera.unproject_unit(np.stack([u.ravel(), v.ravel()], axis=1))  # (H*W, 3), unit rays
    cos_t = np.clip(np.nan_to_num(d[:, 2], nan=0.0), 0.0, 1.0)
    return (cos_t ** 4).reshape(H, W)


def vignetting_map(camera, params: VignettingParams) -> np.ndarray:
    """(H, W) float64 relative illumination V >= 0 for ``camera`` (a scenegen.geometry.camera.Camera)."""
    W, H = camera.width, camera.height
    out = np.ones((H, W), dtype=np.float64)
    if params.natural_cos4:
        out *= cos4_map(camera)
    if any(c != 0.0 for c in params.coeffs):
        cu, cv = params.center_px if params.center_px is not None else (camera.cx, camera.cy)
        u, v = np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64))
        r = np.hypot(u - cu, v - cv) / (0.5 * math.hypot(W, H))
        out *= radial_polynomial(r, params.coeffs)
    return np.clip(out, 0.0, None)
