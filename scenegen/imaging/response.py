"""After the ADC: normalisation, white balance, camera response (tone curve), output quantisation.

* normalise: ``x = (dn - black_level) / (white_level - black_level)`` (1 = ADC full scale);
* white balance: ``x_c *= gain_c`` then clip to [0, 1];
* response: ``srgb`` (IEC 61966-2-1 OETF, the curve the clean path uses), ``gamma``
  (``x ** (1 / gamma)``) or ``linear``;
* quantise: ``round(x * (2^bits - 1))`` to uint8 / uint16.
"""
from __future__ import annotations

import numpy as np

from scenegen.geometry.color import srgb_from_linear

RESPONSES = ("srgb", "gamma", "linear")


def normalise(dn: np.ndarray, black_level_dn: float, white_level_dn: float) -> np.ndarray:
    """ADC output (DN) -> linear signal, 0 at the black level and 1 at ADC full scale (float64)."""
    return (np.asarray(dn, dtype=np.float64) - black_level_dn) / (white_level_dn - black_level_dn)


def white_balance(x: np.ndarray, gains) -> np.ndarray:
    """(H, W, 3) linear signal times per-channel gains, clipped to [0, 1]."""
    return np.clip(np.asarray(x, dtype=np.float64) * np.asarray(gains, dtype=np.float64), 0.0, 1.0)


def encode_response(x: np.ndarray, response: str, gamma: float = 2.2) -> np.ndarray:
    """Linear [0, 1] -> encoded [0, 1] by the camera response curve."""
    x = np.clip(np.asarray(x, dtype=np.float64), 0.0, 1.0)
    if response == "srgb":
        return srgb_from_linear(x)
    if response == "gamma":
        return np.power(x, 1.0 / gamma)
    if response == "linear":
        return x
    raise ValueError(f"response must be one of {RESPONSES}, got {response!r}")
