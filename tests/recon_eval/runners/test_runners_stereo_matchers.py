"""The OpenCV stereo runners' matcher settings: SGBM's smoothness penalties follow OpenCV's
documented P1 = 8 x channels x block^2, P2 = 32 x channels x block^2 for the channels the matcher
is actually given (grey: 1), and the module docstring states the block sizes the code uses."""
from __future__ import annotations

import cv2
import numpy as np
import pytest

from recon_eval.runners import stereo

SHIFT_PX = 8


class _Pair:
    """A dataset stand-in with one rectified pair: a random texture at disparity SHIFT_PX."""

    def __init__(self, rgb: bool):
        rng = np.random.default_rng(0)
        tex = cv2.GaussianBlur(rng.integers(0, 256, (96, 160 + SHIFT_PX)).astype(np.uint8), (0, 0), 1.0)
        left, right = tex[:, :-SHIFT_PX], tex[:, SHIFT_PX:]  # right(x - d) = left(x)
        self.images = tuple(np.repeat(x[..., None], 3, axis=2) if rgb else x for x in (left, right))
        self.disp = np.full(left.shape, float(SHIFT_PX))

    def stereo_left_views(self):
        return ("v0",)

    def stereo_images(self, left):
        return self.images

    def stereo_disparity(self, left):
        return self.disp

    def stereo_noc_mask(self, left):
        return np.ones(self.disp.shape, bool)


@pytest.mark.parametrize("rgb", [False, True])
def test_sgbm_penalties_are_for_the_channels_passed(tmp_path, monkeypatch, rgb):
    made = []
    real = cv2.StereoSGBM_create

    def spy(*args, **kw):
        m = real(*args, **kw)
        made.append(m)
        return m

    monkeypatch.setattr(cv2, "StereoSGBM_create", spy)
    out = stereo.run(_Pair(rgb), tmp_path, {"matcher": "sgbm"})
    (m,) = made
    channels = 1  # the runner converts every pair to grey (to_grey8), colour or not
    b = m.getBlockSize()
    assert b == stereo.BLOCK == 5
    assert (m.getP1(), m.getP2()) == (8 * channels * b**2, 32 * channels * b**2) == (200, 800)
    assert abs(out.metrics["median_signed_err_px"]) < 0.1  # it still matches the shifted texture


def test_docstring_states_the_block_sizes_used():
    bm, _ = stereo._matcher("bm", 640, 1)
    sgbm, _ = stereo._matcher("sgbm", 640, 1)
    doc = " ".join(stereo.__doc__.split())
    assert bm.getBlockSize() == 15 and "StereoBM: block size 15" in doc
    assert sgbm.getBlockSize() == 5 and "block size 5" in doc and "P1 = 200 and P2 = 800" in doc
    assert _matcher_penalties(3) == (600, 2400)  # OpenCV's sample's values, for 3 channels


def _matcher_penalties(channels: int) -> tuple[int, int]:
    m, _ = stereo._matcher("sgbm", 640, channels)
    return m.getP1(), m.getP2()
