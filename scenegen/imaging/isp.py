"""The ISP: the sensor's raw DN -> the delivered image, as a list of named, recorded stages.

The chain (:func:`scenegen.imaging.chain.apply_chain`) builds this list from its parameters
(:func:`scenegen.imaging.chain.isp_stages`) and runs it with :func:`develop`; the same list is
recorded per view in ``cameras.json`` (``views.<view>.raw.isp``), so the delivered PNG is
reproduced from the raw mosaic by these steps alone (docs/image_formation.md, "The ISP"):

==================  ==========================================================================
stage               operation (x: float64 array)
==================  ==========================================================================
demosaic            ``cv2.cvtColor(np.pad(raw, p, mode="reflect"), cv2.<opencv_conversion>)``
                    ``[p:-p, p:-p]`` on the uint16 mosaic (p = ``pad_px``); only with a CFA
normalise           ``x = (dn - black_level_dn) / (white_level_dn - black_level_dn)``
white_balance       ``x = clip(x * gains, 0, 1)`` (gains per R, G, B)
colour_correction   ``x = x @ matrix.T`` (camera RGB -> linear sRGB; identity in this model)
response            ``srgb``: IEC 61966-2-1 OETF; ``gamma``: ``x ** (1 / gamma)``; ``linear``
quantise            ``round(clip(x, 0, 1) * (2^bit_depth - 1))`` to uint8 / uint16
==================  ==========================================================================

There is no sharpening, denoising or JPEG stage: the delivered image is a lossless PNG.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from scenegen.geometry.color import quantise
from scenegen.imaging import bayer, response

STAGE_NAMES = ("demosaic", "normalise", "white_balance", "colour_correction", "response",
               "quantise")
IDENTITY_3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def demosaic_stage(pattern: str, method: str) -> dict[str, Any]:
    return {"stage": "demosaic", "cfa_pattern": pattern, "method": method,
            "opencv_conversion": bayer.opencv_conversion(pattern, method),
            "pad_px": bayer.DEMOSAIC_PAD_PX, "pad_mode": "reflect", "input": "uint16 mosaic, DN"}


def normalise_stage(black_level_dn: float, white_level_dn: float) -> dict[str, Any]:
    return {"stage": "normalise", "black_level_dn": black_level_dn,
            "white_level_dn": white_level_dn,
            "formula": "(dn - black_level_dn) / (white_level_dn - black_level_dn)"}


def white_balance_stage(gains) -> dict[str, Any]:
    return {"stage": "white_balance", "gains": [float(g) for g in gains], "clip": [0.0, 1.0],
            "formula": "clip(x * gains, 0, 1)"}


def colour_correction_stage(matrix=IDENTITY_3) -> dict[str, Any]:
    return {"stage": "colour_correction", "matrix": [[float(v) for v in row] for row in matrix],
            "formula": "x @ matrix.T (camera RGB -> linear sRGB)"}


def response_stage(curve: str, gamma: float) -> dict[str, Any]:
    d: dict[str, Any] = {"stage": "response", "curve": curve}
    if curve == "gamma":
        d["gamma"] = float(gamma)
    return d


def quantise_stage(bit_depth: int) -> dict[str, Any]:
    return {"stage": "quantise", "bit_depth": int(bit_depth),
            "formula": "round(clip(x, 0, 1) * (2^bit_depth - 1))"}


def develop(raw_dn: np.ndarray, stages) -> np.ndarray:
    """Run recorded ISP stages on raw DN: (H, W) uint16 mosaic (with a demosaic stage) or
    (H, W, 3) DN -> the delivered uint8 / uint16 image."""
    x: Any = np.asarray(raw_dn)
    for st in stages:
        name = st["stage"]
        if name == "demosaic":
            x = bayer.demosaic(x, st["cfa_pattern"], st["method"])
        elif name == "normalise":
            x = response.normalise(x, st["black_level_dn"], st["white_level_dn"])
        elif name == "white_balance":
            x = response.white_balance(x, st["gains"])
        elif name == "colour_correction":
            M = np.asarray(st["matrix"], dtype=np.float64)
            if not np.array_equal(M, np.eye(3)):  # the identity changes nothing
                x = np.einsum("ij,...j->...i", M, x)
        elif name == "response":
            x = response.encode_response(x, st["curve"], *([st["gamma"]] if "gamma" in st else []))
        elif name == "quantise":
            x = quantise(x, st["bit_depth"])
        else:
            raise ValueError(f"unknown ISP stage {name!r}; known: {', '.join(STAGE_NAMES)}")
    return x
