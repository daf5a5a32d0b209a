"""Fixtures of the imaging tests."""
from __future__ import annotations

import cv2
import numpy as np
import pytest


def _develop_from_record(raw: np.ndarray, stages) -> np.ndarray:
    """The ISP stages as docs/image_formation.md ("The ISP") states them, from the JSON record
    alone: no scenegen code."""
    x = raw
    for st in stages:
        kind = st["stage"]
        if kind == "demosaic":
            p = st["pad_px"]
            x = cv2.cvtColor(np.pad(x, p, mode=st["pad_mode"]), getattr(cv2, st["opencv_conversion"]))
            x = x[p:-p, p:-p]
        elif kind == "normalise":
            b, w = st["black_level_dn"], st["white_level_dn"]
            x = (x.astype(np.float64) - b) / (w - b)
        elif kind == "white_balance":
            x = np.clip(x * np.asarray(st["gains"]), *st["clip"])
        elif kind == "colour_correction":
            x = x @ np.asarray(st["matrix"]).T
        elif kind == "response":
            x = np.clip(x, 0.0, 1.0)
            if st["curve"] == "srgb":  # IEC 61966-2-1
                x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
            elif st["curve"] == "gamma":
                x = np.power(x, 1.0 / st["gamma"])
        elif kind == "quantise":
            top = 2 ** st["bit_depth"] - 1
            x = np.rint(np.clip(x, 0.0, 1.0) * top).astype(np.uint8 if st["bit_depth"] == 8 else np.uint16)
        else:
            raise AssertionError(f"undocumented stage {kind}")
    return x


@pytest.fixture(scope="session")
def develop_from_record():
    """The ISP stages of a raw record run by OpenCV and numpy as docs/image_formation.md states
    them (no scenegen code): ``develop_from_record(raw_mosaic, record["isp"]) -> image``."""
    return _develop_from_record
