"""The raw output of a camera: which files, and the colour data a raw decoder needs.

``imaging: {raw: ...}`` (opt-in per camera) writes the sensor's mosaic, the ADC output of stage 5
before demosaicing, as ``raw/<view>.dng`` and/or a 16-bit grey ``images/<view>_raw.png``
(:mod:`scenegen.dataset.layout`). DN below the black level are kept down to 0 (the ADC's own
floor) unless the sensor declares ``black_level_clip``.

Colour model (the chain's own, docs/image_formation.md): the render's linear RGB is linear sRGB
(BT.709 primaries, D65), and a camera pixel of colour ``c`` collects ``k_c L_c`` electrons
(``k = electrons_per_radiance``: QE, wavelength, optics, exposure; no crosstalk). So

* camera RGB = ``diag(k) @ SRGB_FROM_XYZ @ XYZ``: the DNG ``ColorMatrix1`` (XYZ -> camera, under
  D65) is ``diag(k / max(k)) @ inv(XYZ_FROM_LINEAR_SRGB)``, scaled as the DNG spec asks (the
  illuminant's white, XYZ of sRGB (1, 1, 1), maps to a camera RGB whose largest value is 1);
* a neutral surface gives camera RGB proportional to ``k``; ``AsShotNeutral`` is ``1 / gains``
  of the white balance actually applied, normalised to G = 1 (``k / k_G`` for ``auto``);
* after that white balance, camera RGB is linear sRGB: the colour correction is the identity.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry.color import XYZ_FROM_LINEAR_SRGB


@dataclass(frozen=True, kw_only=True)
class RawOutput:
    """Which raw files a camera writes (metadata: ``scenegen.spec.model.cameras``)."""

    dng: bool = True  # raw/<view>.dng: the mosaic with CFA, black/white levels, colour matrix
    png: bool = False  # images/<view>_raw.png: the same mosaic as a 16-bit grey PNG


def color_matrix_xyz_to_camera(electrons_per_radiance) -> np.ndarray:
    """(3, 3) DNG ColorMatrix1: CIE XYZ (D65) -> camera RGB, largest response to white = 1."""
    k = np.asarray(electrons_per_radiance, dtype=np.float64)
    return (k / k.max())[:, None] * np.linalg.inv(XYZ_FROM_LINEAR_SRGB)


def as_shot_neutral(white_balance_gains) -> tuple[float, float, float]:
    """DNG AsShotNeutral: camera R, G, B of a neutral surface, ``gain_G / gain_c``."""
    g = [float(x) for x in white_balance_gains]
    return tuple(g[1] / x for x in g)
