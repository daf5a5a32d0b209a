"""The DNG codec: an exact round trip through our own reader, and an independent raw decoder
(LibRaw, through rawpy) that reads our bytes to the same mosaic, levels, CFA pattern, white
balance, colour matrix and orientation."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import rawpy

from scenegen.dataset import codecs as sio
from scenegen.dataset.codecs.dng import RATIONAL_DENOMINATOR, DngRaw, decode_dng, encode_dng
from scenegen.imaging.raw import as_shot_neutral, color_matrix_xyz_to_camera

PATTERNS = ("RGGB", "BGGR", "GRBG", "GBRG")
#: LibRaw's own linear sRGB -> XYZ table (``xyz_rgb`` in LibRaw/dcraw), used by its DNG colour
#: path: rgb_cam = inverse(row-normalised(ColorMatrix1 @ xyz_rgb)) (dcraw's cam_xyz_coeff).
LIBRAW_XYZ_RGB = np.array([[0.412453, 0.357580, 0.180423], [0.212671, 0.715160, 0.072169],
                           [0.019334, 0.119193, 0.950227]])
#: Rationals hold 6 decimals; LibRaw reads them as float32.
RATIONAL_TOL = 1.0 / RATIONAL_DENOMINATOR


def _raw(pattern="RGGB", black=64, white=4095, shape=(48, 64), seed=0, k=(57044.8, 64806.6, 43485.0),
         gains=(1.136, 1.0, 1.49)):
    m = np.random.default_rng(seed).integers(0, white + 1, shape).astype(np.uint16)
    return DngRaw(mosaic=m, cfa_pattern=pattern, black_level_dn=black, white_level_dn=white,
                  as_shot_neutral=as_shot_neutral(gains), color_matrix=color_matrix_xyz_to_camera(k),
                  camera_model="scenegen test cam")


@pytest.mark.parametrize("pattern", PATTERNS)
def test_round_trip_is_exact(tmp_path, pattern):
    r = _raw(pattern, shape=(37, 51))  # odd sizes: the pattern's phase is the file's, not the size's
    sio.write_dng(tmp_path / "a.dng", r)
    d = sio.read_dng(tmp_path / "a.dng")
    assert d.mosaic.dtype == np.uint16 and np.array_equal(d.mosaic, r.mosaic)
    assert (d.cfa_pattern, d.black_level_dn, d.white_level_dn, d.orientation) == (pattern, 64.0, 4095, 1)
    assert d.camera_model == "scenegen test cam" and d.make == "scenegen"
    assert np.allclose(d.as_shot_neutral, r.as_shot_neutral, atol=RATIONAL_TOL)
    assert np.allclose(d.color_matrix, r.color_matrix, atol=RATIONAL_TOL)
    assert encode_dng(d) == encode_dng(r)  # what is read back writes the same bytes


def test_bytes_are_deterministic_and_a_fractional_black_level_is_a_rational():
    assert encode_dng(_raw()) == encode_dng(_raw())
    d = decode_dng(encode_dng(_raw(black=64.5)))
    assert d.black_level_dn == 64.5


@pytest.mark.parametrize("bad", [dict(mosaic=np.zeros((4, 4), np.float32)), dict(cfa_pattern="RGBX"),
                                 dict(black_level_dn=4095), dict(color_matrix=np.eye(4))])
def test_refused(bad):
    with pytest.raises(ValueError):
        encode_dng(dataclasses.replace(_raw(), **bad))


def test_not_a_dng_is_a_value_error(tmp_path):
    (tmp_path / "x.dng").write_bytes(b"not a tiff at all")
    with pytest.raises(ValueError, match="x.dng"):
        sio.read_dng(tmp_path / "x.dng")
    with pytest.raises(ValueError, match="missing tag"):
        decode_dng(b"II*\0" + (8).to_bytes(4, "little") + (0).to_bytes(2, "little") + bytes(4))


@pytest.mark.parametrize("pattern", PATTERNS)
@pytest.mark.parametrize("black,white", [(64, 4095), (64, 1023), (2048, 16383)])
def test_libraw_reads_what_we_wrote(tmp_path, pattern, black, white):
    gains = (0.98, 1.0, 1.45)
    r = _raw(pattern, black=black, white=white, gains=gains)
    path = tmp_path / "a.dng"
    sio.write_dng(path, r)
    with rawpy.imread(str(path)) as raw:
        assert np.array_equal(raw.raw_image, r.mosaic)  # the mosaic, every DN
        assert np.array_equal(raw.raw_image_visible, r.mosaic)  # no margins
        assert raw.black_level_per_channel == [black] * 4 and raw.white_level == white
        desc = raw.color_desc.decode()  # LibRaw's colour indices, e.g. 'RGBG'
        assert "".join(desc[i] for i in raw.raw_pattern.ravel()) == pattern
        assert raw.sizes.flip == 0  # Orientation 1: no rotation or mirroring
        # as-shot white balance: LibRaw's multipliers are 1 / AsShotNeutral = our gains
        assert np.allclose(raw.camera_whitebalance[:3], gains, rtol=1e-5)
        # ColorMatrix1 is read and used: LibRaw's camera -> sRGB matrix follows from it, and
        # with our colour model (no crosstalk) it is the identity
        cm = decode_dng(path.read_bytes()).color_matrix
        cam_rgb = cm @ LIBRAW_XYZ_RGB
        expected = np.linalg.inv(cam_rgb / cam_rgb.sum(axis=1, keepdims=True))
        assert np.abs(raw.color_matrix[:, :3] - expected).max() < 1e-5
        assert np.abs(raw.color_matrix[:, :3] - np.eye(3)).max() < 1e-5
