"""Exposure: scene radiance -> mean photons per pixel (the camera equation).

Radiometric model (stated once, used everywhere). The clean render's linear RGB values are
radiance ``L`` in W m^-2 sr^-1 per channel (as the spec's lights are). Each channel is treated as
monochromatic at a representative wavelength ``lambda_c`` of that channel. For an object far
from the lens (magnification << 1), the on-axis irradiance on the sensor is the camera equation

    E = L * pi * T / (4 N^2)                    [W m^-2]   (Slater, Remote Sensing, eq. 8.7;
                                                            EMVA 1288 R4.0 sec. 2.1)

with ``N`` the f-number and ``T`` the lens transmittance. Off-axis falloff (cos^4 and mechanical
vignetting) is the vignetting stage's factor ``V(u, v)``. A pixel of pitch ``p`` (area ``p^2``,
fill factor and microlenses folded into the QE, as EMVA 1288 does) exposed for ``t`` seconds
receives

    mu_p = E * V * p^2 * t * lambda_c / (h c)   [photons]

and ``photons_per_radiance`` = ``pi T p^2 lambda / (4 N^2 h c)`` is the photons per pixel per
second per unit radiance on the axis. Doubling ``t`` or halving ``N^2`` doubles the signal.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from scenegen.geometry.tof import SPEED_OF_LIGHT_M_S

PLANCK_J_S = 6.62607015e-34  # h, exact (SI 2019)
LIGHT_SPEED_M_S = SPEED_OF_LIGHT_M_S  # c, exact: stated once in scenegen.geometry.tof


@dataclass(frozen=True, kw_only=True)
class ExposureParams:
    exposure_time_s: float = 0.01  # integration time t, seconds (> 0)
    f_number: float = 2.8  # N, for the irradiance only (the camera equation); > 0
    lens_transmittance: float = 0.9  # T in (0, 1]
    gain_db: float = 0.0  # analog gain: system gain K = K_0 * 10**(gain_db / 20)


def photons_per_radiance(exposure: ExposureParams, pixel_pitch_um: float,
                         wavelength_nm: float) -> float:
    """Photons per pixel per second per unit radiance (W m^-2 sr^-1), on the optical axis."""
    irradiance_per_radiance = math.pi * exposure.lens_transmittance / (4.0 * exposure.f_number ** 2)
    area_m2 = (pixel_pitch_um * 1e-6) ** 2
    photon_energy_j = PLANCK_J_S * LIGHT_SPEED_M_S / (wavelength_nm * 1e-9)
    return irradiance_per_radiance * area_m2 / photon_energy_j


def mean_photons(linear_rgb: np.ndarray, vignetting: np.ndarray, exposure: ExposureParams,
                 pixel_pitch_um: float, wavelengths_nm) -> np.ndarray:
    """Mean photons per pixel and channel.

    linear_rgb: (H, W, 3) radiance, W m^-2 sr^-1 (negative values are clipped to 0).
    vignetting: (H, W) relative illumination V (1 = on-axis irradiance).
    wavelengths_nm: 3 representative wavelengths (R, G, B), nm.
    Returns (H, W, 3) float64 photons.
    """
    scale = np.array([photons_per_radiance(exposure, pixel_pitch_um, w) for w in wavelengths_nm])
    L = np.clip(np.asarray(linear_rgb, dtype=np.float64), 0.0, None)
    return L * (np.asarray(vignetting, dtype=np.float64)[..., None] * scale * exposure.exposure_time_s)
