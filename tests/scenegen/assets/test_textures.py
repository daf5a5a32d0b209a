"""Tests for scenegen.assets.textures: layout, range, determinism, statistics, features, file decoding."""
from __future__ import annotations

import cv2
import numpy as np
import pytest

from scenegen.assets import textures
from scenegen.geometry.color import linear_from_srgb, srgb_from_linear

RANDOM_KINDS = {
    "noise": lambda seed: textures.noise(128, seed=seed),
    "speckle": lambda seed: textures.speckle(128, seed=seed),
    "natural": lambda seed: textures.natural(128, seed=seed),
}


def _gray8(img: np.ndarray) -> np.ndarray:
    """Linear RGB float -> 8-bit sRGB grey, as a camera image of the texture would be stored."""
    srgb = (srgb_from_linear(img) * 255 + 0.5).astype(np.uint8)
    return cv2.cvtColor(srgb, cv2.COLOR_RGB2GRAY)


@pytest.mark.parametrize("kind", list(RANDOM_KINDS))
class TestRandomCommon:
    def test_same_seed_bitwise_equal(self, kind):
        a, b = RANDOM_KINDS[kind](3), RANDOM_KINDS[kind](3)
        assert a.tobytes() == b.tobytes()
        assert not np.array_equal(a, RANDOM_KINDS[kind](4))

    def test_dtype_shape_range(self, kind):
        a = RANDOM_KINDS[kind](0)
        assert a.dtype == np.float32 and a.shape == (128, 128, 3)
        assert a.min() >= 0.0 and a.max() <= 1.0 and np.all(np.isfinite(a))
        assert a.std() > 0.05  # not flat


def test_non_square_size_is_width_height():
    for f in (textures.noise, textures.speckle, textures.natural):
        assert f((96, 64), seed=0).shape == (64, 96, 3)


class TestCheckerboard:
    def test_exact_layout(self):
        c0, c1 = (0.9, 0.5, 0.1), (0.0, 0.25, 1.0)
        img = textures.checkerboard(5, 3, colors=(c0, c1), px_per_square=7)
        assert img.shape == (21, 35, 3) and img.dtype == np.float32
        rows, cols = np.mgrid[0:21, 0:35]
        parity = (rows // 7 + cols // 7) % 2
        expected = np.where(parity[..., None] == 0, np.float32(c0), np.float32(c1))
        assert np.array_equal(img, expected)  # top-left square is colors[0], edges on pixel edges

    def test_grey_colors_and_errors(self):
        img = textures.checkerboard(2, 2, colors=(1.0, 0.0), px_per_square=1)
        assert np.array_equal(img[..., 0], [[1, 0], [0, 1]])
        with pytest.raises(ValueError, match="px_per_square"):
            textures.checkerboard(2, 2, px_per_square=0)
        with pytest.raises(ValueError, match="colors"):
            textures.checkerboard(2, 2, colors=((2.0, 0, 0), (0, 0, 0)))


class TestNoise:
    def test_uses_the_colour_ramp_and_tiles(self):
        lo, hi = (0.1, 0.2, 0.3), (0.6, 0.7, 0.8)
        img = textures.noise(128, seed=1, colors=(lo, hi))
        assert np.allclose(img.min(axis=(0, 1)), lo, atol=1e-6)
        assert np.allclose(img.max(axis=(0, 1)), hi, atol=1e-6)
        # Periodic: the jump across the wrap-around edge is no bigger than between inner columns.
        g = img[..., 0]
        inner = np.abs(np.diff(g, axis=1)).max()
        assert np.abs(g[:, 0] - g[:, -1]).max() <= inner + 1e-6

    def test_octaves_add_detail(self):
        smooth = textures.noise(128, seed=0, octaves=1)
        rough = textures.noise(128, seed=0, octaves=6)
        lap = [np.abs(cv2.Laplacian(x[..., 0], cv2.CV_32F)).mean() for x in (smooth, rough)]
        assert lap[1] > 3 * lap[0]


class TestSpeckle:
    # The covered fraction is 1 - exp(-lam pi r^2) in expectation for Poisson discs; the render
    # merges overlapping antialiased edges with max() (not a union of sub-pixel areas), which
    # biases coverage by up to ~0.015 at r = 2 px (measured 0.000 .. 0.012 over these cases);
    # sampling noise at 256^2 px is ~0.003.
    COVERAGE_ABS_TOL = 0.02

    @pytest.mark.parametrize("density", [0.1, 0.3, 0.5, 0.7])
    @pytest.mark.parametrize("radius", [2.0, 4.0])
    def test_covered_fraction_matches_density(self, density, radius):
        bg, fg = 0.9, 0.02
        img = textures.speckle(256, seed=11, density=density, dot_radius_px=radius,
                               background=bg, foreground=fg)
        coverage = (bg - img[..., 0].astype(np.float64)) / (bg - fg)
        assert abs(coverage.mean() - density) <= self.COVERAGE_ABS_TOL

    def test_isotropic_high_contrast(self):
        img = textures.speckle(256, seed=2, density=0.5, dot_radius_px=2.0)[..., 0]
        assert img.min() == pytest.approx(0.02, abs=1e-6) and img.max() == pytest.approx(0.9)
        # Gradient energy is the same along x and y (isotropic), within sampling noise (~3%).
        gx = np.abs(np.diff(img, axis=1)).mean()
        gy = np.abs(np.diff(img, axis=0)).mean()
        assert abs(gx / gy - 1) < 0.05

    def test_rejects_bad_density(self):
        with pytest.raises(ValueError, match="density"):
            textures.speckle(64, density=1.0)


class TestNatural:
    # Measured with OpenCV 4.14 SIFT defaults on 512^2 px: 3530..4204 keypoints for seeds 0..4;
    # the smooth 'noise' texture gives ~10..30 (see the control below). 2500 leaves margin for
    # seed variation while still failing on a texture with few features.
    MIN_SIFT_KEYPOINTS_512 = 2500

    @pytest.mark.parametrize("seed", [0, 1])
    def test_many_sift_keypoints(self, seed):
        sift = cv2.SIFT_create()
        n = len(sift.detect(_gray8(textures.natural(512, seed=seed)), None))
        assert n >= self.MIN_SIFT_KEYPOINTS_512

    def test_control_texture_fails_the_threshold(self):
        sift = cv2.SIFT_create()
        n = len(sift.detect(_gray8(textures.noise(512, seed=0)), None))
        assert n < self.MIN_SIFT_KEYPOINTS_512 / 10

    def test_fully_covered_by_leaves(self):
        """Dead leaves cover the plane: few pixels are left at the background colour."""
        img = textures.natural(256, seed=3, fine_noise=0.0, supersample=1)
        colors, counts = np.unique(img.reshape(-1, 3), axis=0, return_counts=True)
        assert counts.max() < 0.2 * img.shape[0] * img.shape[1]  # no single colour dominates
        assert len(colors) > 200


class TestLoadImage:
    def test_png8_rgb_order_and_decoding(self, tmp_path):
        rgb = np.zeros((2, 3, 3), np.uint8)
        rgb[0, 0] = (255, 0, 0)
        rgb[0, 1] = (0, 128, 0)
        rgb[1, 2] = (0, 0, 64)
        path = tmp_path / "t.png"
        cv2.imwrite(str(path), rgb[..., ::-1])  # cv2 writes BGR
        img = textures.load_image(path)
        assert img.shape == (2, 3, 3) and img.dtype == np.float32
        assert np.allclose(img, linear_from_srgb(rgb / 255.0), atol=1e-7)
        assert img[0, 0, 0] == 1.0 and img[0, 0, 1] == 0.0

    def test_png16_grey_and_rgba(self, tmp_path):
        g16 = np.array([[0, 32768, 65535]], np.uint16)
        cv2.imwrite(str(tmp_path / "g.png"), g16)
        img = textures.load_image(tmp_path / "g.png")
        assert img.shape == (1, 3, 3)
        assert np.allclose(img[..., 1], linear_from_srgb(g16 / 65535.0), atol=1e-7)
        rgba = np.full((2, 2, 4), 200, np.uint8)
        cv2.imwrite(str(tmp_path / "a.png"), rgba)
        assert textures.load_image(tmp_path / "a.png").shape == (2, 2, 3)

    def test_jpeg(self, tmp_path):
        cv2.imwrite(str(tmp_path / "j.jpg"), np.full((8, 8, 3), 128, np.uint8))
        img = textures.load_image(tmp_path / "j.jpg")
        assert np.allclose(img, linear_from_srgb(128 / 255), atol=0.01)

    def test_errors_name_the_file(self, tmp_path):
        with pytest.raises(ValueError, match="missing.png.*not found"):
            textures.load_image(tmp_path / "missing.png")
        (tmp_path / "junk.png").write_bytes(b"not a png")
        with pytest.raises(ValueError, match="junk.png"):
            textures.load_image(tmp_path / "junk.png")


class TestMakeTexture:
    def test_dispatch_matches_direct_call(self):
        a = textures.make_texture("speckle", {"size_px": 64, "density": 0.4}, seed=9)
        assert a.tobytes() == textures.speckle(64, seed=9, density=0.4).tobytes()
        b = textures.make_texture("checkerboard", {"squares_u": 3, "squares_v": 2}, seed=1)
        assert b.tobytes() == textures.checkerboard(3, 2).tobytes()

    def test_image_kind(self, tmp_path):
        cv2.imwrite(str(tmp_path / "i.png"), np.zeros((4, 5, 3), np.uint8))
        assert textures.make_texture("image", {"path": tmp_path / "i.png"}).shape == (4, 5, 3)

    def test_errors_name_kind_and_param(self):
        with pytest.raises(ValueError, match="unknown texture kind 'marble'"):
            textures.make_texture("marble", {}, seed=0)
        with pytest.raises(ValueError, match=r"'noise'.*\['octave'\].*octaves"):
            textures.make_texture("noise", {"octave": 3}, seed=0)
        with pytest.raises(ValueError, match=r"'speckle'.*\['seed'\]"):
            textures.make_texture("speckle", {"seed": 3}, seed=0)
        with pytest.raises(ValueError, match="'image'.*path"):
            textures.make_texture("image", {}, seed=0)
        with pytest.raises(ValueError, match="persistence"):
            textures.make_texture("noise", {"persistence": 2.0}, seed=0)
