"""Bayer mosaic and OpenCV demosaicing."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen.imaging import bayer

#: A smooth image (period >= 32 px) demosaics back to within 0.5 % of full scale, away from the
#: 2-pixel border where OpenCV's interpolation has fewer neighbours.
ROUND_TRIP_TOL = 0.005
BORDER = 2


@pytest.mark.parametrize("pattern", bayer.PATTERNS)
def test_channel_at_each_pixel(pattern):
    ch = bayer.channel_map(pattern, 5, 7)
    letters = np.array(list("RGB"))[ch]
    assert "".join(letters[:2, :2].ravel()) == pattern  # the top-left block, row by row
    assert np.array_equal(ch[2:4, 2:4], ch[:2, :2]) and ch.shape == (5, 7)
    rgb = np.zeros((5, 7, 3), np.uint16)
    rgb[..., 0], rgb[..., 1], rgb[..., 2] = 100, 200, 300
    assert np.array_equal(bayer.mosaic(rgb, pattern), (ch.astype(np.uint16) + 1) * 100)


@pytest.mark.parametrize("method", bayer.DEMOSAIC_METHODS)
@pytest.mark.parametrize("pattern", bayer.PATTERNS)
def test_demosaic_constant_colour_is_exact(pattern, method):
    """Catches a wrong OpenCV code: swapped R/B or misplaced G would change the colour."""
    rgb = np.empty((16, 16, 3), np.uint16)
    rgb[...] = (1000, 20000, 40000)
    out = bayer.demosaic(bayer.mosaic(rgb, pattern), pattern, method)
    assert out.dtype == np.uint16
    assert np.array_equal(out[BORDER:-BORDER, BORDER:-BORDER], rgb[BORDER:-BORDER, BORDER:-BORDER])


@pytest.mark.parametrize("method", bayer.DEMOSAIC_METHODS)
@pytest.mark.parametrize("pattern", bayer.PATTERNS)
def test_round_trip_smooth_image(pattern, method):
    H, W = 64, 80
    v, u = np.mgrid[0:H, 0:W].astype(np.float64)
    rgb = np.stack([0.5 + 0.4 * np.sin(u / 9.0), 0.5 + 0.4 * np.cos(v / 11.0),
                    0.5 + 0.3 * np.sin((u + v) / 13.0)], axis=2)
    img = np.rint(rgb * 65535).astype(np.uint16)
    out = bayer.demosaic(bayer.mosaic(img, pattern), pattern, method)
    err = np.abs(out.astype(np.float64) - img)[BORDER:-BORDER, BORDER:-BORDER] / 65535
    assert err.max() < ROUND_TRIP_TOL


def test_bad_pattern_and_method():
    with pytest.raises(ValueError, match="Bayer pattern"):
        bayer.channel_map("RGBG", 2, 2)
    with pytest.raises(ValueError, match="demosaic method"):
        bayer.demosaic(np.zeros((4, 4), np.uint16), "RGGB", "vng")
