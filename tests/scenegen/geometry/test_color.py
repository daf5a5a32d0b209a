"""The image value conventions: sRGB transfer functions, quantisation, 16 -> 8 bits, grey."""
import cv2
import numpy as np
import pytest

from scenegen.geometry.color import linear_from_srgb, quantise, srgb_from_linear, srgb_image, to_grey8, to_uint8


class TestSrgb:
    def test_srgb_eotf_known_values(self):
        # IEC 61966-2-1: 0.5 encoded -> 0.21404; 0.04045 is the segment joint; 1 -> 1.
        assert linear_from_srgb(0.5) == pytest.approx(0.214041140, abs=1e-9)
        assert linear_from_srgb(0.04045) == pytest.approx(0.04045 / 12.92)
        assert linear_from_srgb(1.0) == pytest.approx(1.0)
        x = np.linspace(0, 1, 101)
        assert np.allclose(srgb_from_linear(linear_from_srgb(x)), x, atol=1e-12)

    def test_oetf_known_values_and_clipping(self):
        # 0.0031308 is the segment joint: 12.92 x below, 1.055 x^(1/2.4) - 0.055 above
        assert srgb_from_linear(0.0031308) == pytest.approx(0.0031308 * 12.92)
        assert srgb_from_linear(0.214041140) == pytest.approx(0.5, abs=1e-9)
        assert srgb_from_linear(-1.0) == 0.0 and srgb_from_linear(2.0) == pytest.approx(1.0)


class TestQuantise:
    def test_round_to_nearest_and_clip(self):
        x = np.array([-0.1, 0.0, 0.5 / 255, 0.49 / 255 + 1 / 255, 1.0, 1.5])
        assert quantise(x, 8).tolist() == [0, 0, 0, 1, 255, 255]  # rint: 0.5 -> 0 (half to even)
        assert quantise(np.array([1.0]), 16).dtype == np.uint16 and quantise(np.array([1.0]), 16)[0] == 65535
        with pytest.raises(ValueError, match="bit_depth"):
            quantise(x, 12)

    def test_srgb_image_is_quantised_oetf(self):
        lin = np.random.default_rng(0).uniform(-0.2, 1.2, (4, 5, 3))
        assert np.array_equal(srgb_image(lin, 8), np.rint(srgb_from_linear(lin) * 255).astype(np.uint8))


class TestBitDepthAndGrey:
    def test_uint16_to_uint8_inverts_x257(self):
        x8 = np.arange(256, dtype=np.uint8)
        assert np.array_equal(to_uint8(x8.astype(np.uint16) * 257), x8)
        assert to_uint8(np.array([128, 129], np.uint16)).tolist() == [0, 1]  # 128/257 < 0.5 < 129/257
        assert to_uint8(x8) is x8

    def test_grey_is_opencvs(self):
        rgb = np.random.default_rng(1).integers(0, 256, (6, 7, 3), dtype=np.uint8)
        assert np.array_equal(to_grey8(rgb), cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
        assert np.array_equal(to_grey8(rgb.astype(np.uint16) * 257), to_grey8(rgb))
        with pytest.raises(ValueError, match="uint8 or uint16"):
            to_uint8(np.zeros(3, np.float32))
