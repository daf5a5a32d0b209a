"""Image value conventions, stated once: the sRGB transfer functions, quantisation to 8/16 bits,
16 -> 8 bit conversion and RGB -> grey.

* Linear values are radiance-proportional floats, 1.0 = the top of the encoded range.
* sRGB (IEC 61966-2-1): OETF ``12.92 x`` for ``x <= 0.0031308``, else ``1.055 x^(1/2.4) - 0.055``;
  the EOTF is its inverse (threshold 0.04045).
* Quantisation to ``b`` bits: ``round(clip(x, 0, 1) * (2^b - 1))`` to uint8 / uint16.
* 16 -> 8 bits: ``round(x / 257)`` (257 = 65535 / 255, so it inverts ``x8 * 257`` exactly).
* Grey: OpenCV's ``COLOR_RGB2GRAY`` (ITU-R BT.601 weights, OpenCV's fixed-point rounding) of the
  8-bit image, so detectors see what a user of cv2 would feed them.
* Colour space of the linear values: linear sRGB, i.e. the ITU-R BT.709 primaries with the D65
  white (what Mitsuba's RGB variants render and what the sRGB encoding above assumes);
  ``XYZ_FROM_LINEAR_SRGB`` maps it to CIE 1931 XYZ with white (1, 1, 1) -> Y = 1.
"""
from __future__ import annotations

import numpy as np

BIT_DEPTHS = (8, 16)
#: CIE 1931 xy chromaticities of the sRGB (BT.709) primaries R, G, B and of the D65 white
#: (IEC 61966-2-1).
SRGB_PRIMARIES_XY = ((0.64, 0.33), (0.30, 0.60), (0.15, 0.06))
D65_WHITE_XY = (0.3127, 0.3290)


def rgb_to_xyz_matrix(primaries_xy, white_xy) -> np.ndarray:
    """(3, 3) linear RGB -> XYZ of an RGB space given by its primaries' and white's xy, scaled
    so that RGB (1, 1, 1) is the white with Y = 1 (the usual derivation, e.g. SMPTE RP 177)."""
    def xyz(x, y):
        return np.array([x / y, 1.0, (1.0 - x - y) / y])

    P = np.stack([xyz(*p) for p in primaries_xy], axis=1)  # columns: the primaries, Y = 1
    return P * np.linalg.solve(P, xyz(*white_xy))


#: Linear sRGB -> CIE XYZ (D65): 0.4124 0.3576 0.1805 / 0.2126 0.7152 0.0722 / 0.0193 0.1192 0.9505.
XYZ_FROM_LINEAR_SRGB = rgb_to_xyz_matrix(SRGB_PRIMARIES_XY, D65_WHITE_XY)


def srgb_from_linear(x) -> np.ndarray:
    """sRGB encoding (OETF) of linear values, clipped to [0, 1] first: float64 in [0, 1]."""
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def linear_from_srgb(c) -> np.ndarray:
    """sRGB decoding (EOTF): encoded values in [0, 1] -> linear values in [0, 1] (float64)."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def quantise(x, bit_depth: int) -> np.ndarray:
    """[0, 1] -> uint8 / uint16, rounding to nearest (values outside [0, 1] are clipped)."""
    if bit_depth not in BIT_DEPTHS:
        raise ValueError(f"bit_depth must be one of {BIT_DEPTHS}, got {bit_depth!r}")
    top = (1 << bit_depth) - 1
    return np.rint(np.clip(x, 0.0, 1.0) * top).astype(np.uint8 if bit_depth == 8 else np.uint16)


def srgb_image(linear_rgb, bit_depth: int) -> np.ndarray:
    """Linear radiance -> the sRGB-encoded uint8 / uint16 image (clipped at 0 and 1)."""
    return quantise(srgb_from_linear(linear_rgb), bit_depth)


def to_uint8(image) -> np.ndarray:
    """A uint8 image of a uint8 (unchanged) or uint16 image (``round(x / 257)``)."""
    a = np.asarray(image)
    if a.dtype == np.uint8:
        return a
    if a.dtype != np.uint16:
        raise ValueError(f"stored images are uint8 or uint16, got {a.dtype}")
    return np.rint(a.astype(np.float64) / 257.0).astype(np.uint8)


def to_grey8(image) -> np.ndarray:
    """(H, W) uint8 grey of an (H, W) or (H, W, 3) RGB uint8/uint16 image (for feature detectors)."""
    # cv2 on use: the conversion must be OpenCV's own, and this module is otherwise numpy only
    import cv2

    a = to_uint8(image)
    return cv2.cvtColor(a, cv2.COLOR_RGB2GRAY) if a.ndim == 3 else a
