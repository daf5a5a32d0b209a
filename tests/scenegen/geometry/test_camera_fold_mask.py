"""A real wide-lens OpenCV calibration whose radial polynomial folds inside the image corners:
refused by default, accepted with `mask_beyond_fold`, and the pixels without a ray are exactly
those beyond the image of the fold radius, computed here from scratch."""
import numpy as np
import pytest

from scenegen.errors import SpecError
from scenegen.geometry.camera import Camera
from scenegen.geometry.camera.validity import FoldError
from scenegen.geometry.conventions import pixel_centers
from scenegen.spec import parse_spec

# k1 = -0.4, k2 = 0.03: r_d(r) = r (1 + k1 r^2 + k2 r^4) peaks at r = 0.972 (r_d = 0.6307); the
# 640x480 image's corners at f = 560 px reach r_d = 0.714.
K1, K2, F, W, H = -0.4, 0.03, 560.0, 640, 480
CX, CY = 319.5, 239.5


def fold_distorted_radius(k1, k2):
    """From scratch: the smallest r > 0 with d r_d / d r = 1 + 3 k1 r^2 + 5 k2 r^4 = 0, and r_d there."""
    r2 = min(x.real for x in np.roots([5 * k2, 3 * k1, 1.0]) if abs(x.imag) < 1e-12 and x.real > 0)
    return np.sqrt(r2) * (1 + k1 * r2 + k2 * r2 * r2)


def independent_mask(width, height, f, cx, cy, k1, k2):
    uv = pixel_centers(width, height)
    r_d = np.hypot((uv[..., 0] - cx) / f, (uv[..., 1] - cy) / f)
    return r_d > fold_distorted_radius(k1, k2)


def test_a_folding_calibration_is_refused_and_the_message_names_the_option(tmp_path):
    with pytest.raises(FoldError, match="folds over inside the 640x480 image"):
        Camera("opencv", W, H, F, F, CX, CY, 0.0, (K1, K2, 0, 0, 0))
    text = f"""name: f
cameras:
  wide: {{model: opencv, size: [{W}, {H}], fx: {F}, fy: {F}, dist: [{K1}, {K2}, 0, 0, 0]}}
"""
    with pytest.raises(SpecError, match=r"f.yaml:3: cameras.wide.dist: impossible camera: .*set "
                                        r"`mask_beyond_fold: true` on the camera"):
        parse_spec(text, file="f.yaml", base_dir=tmp_path)


@pytest.mark.parametrize("f,cx,cy", [(F, CX, CY), (600.0, 300.2, 251.7)])
def test_the_pixels_without_a_ray_are_those_beyond_the_fold(f, cx, cy):
    cam = Camera("opencv", W, H, f, f, cx, cy, 0.0, (K1, K2, 0, 0, 0), mask_beyond_fold=True)
    got = cam.no_ray_mask()
    want = independent_mask(W, H, f, cx, cy, K1, K2)
    assert want.sum() > 1000  # the corners fold
    assert np.array_equal(got, want), int((got != want).sum())
    # every other pixel has a ray that projects back onto it
    rays = cam.unproject_unit(pixel_centers(W, H).reshape(-1, 2))
    ok = ~got.reshape(-1)
    assert np.isfinite(rays[ok]).all() and np.isnan(rays[~ok]).all()
    back = cam.project(rays[ok])
    np.testing.assert_allclose(back, pixel_centers(W, H).reshape(-1, 2)[ok], atol=1e-6)


def test_the_camera_record_says_so_and_round_trips():
    cam = Camera("opencv", W, H, F, F, CX, CY, 0.0, (K1, K2, 0, 0, 0), mask_beyond_fold=True)
    d = cam.to_dict()
    assert d["mask_beyond_fold"] is True
    assert d["pixels_beyond_fold"] == int(independent_mask(W, H, F, CX, CY, K1, K2).sum())
    assert Camera.from_dict(d) == cam
    plain = Camera("opencv", W, H, F, F, CX, CY, 0.0, (-0.1, 0.01, 0, 0, 0))
    assert "mask_beyond_fold" not in plain.to_dict()  # unchanged records for every other camera
    with pytest.raises(ValueError, match="opencv model"):
        Camera("fisheye", W, H, F, F, CX, CY, 0.0, (0.1, 0, 0, 0), mask_beyond_fold=True)
