"""Poly Haven HDRIs (equirectangular .hdr / .exr, previewed in Blender): the one conversion,
``BLENDER_ENVMAP_ROTATION_Z_DEG``, against a transliteration of Cycles' own mapping
(``intern/cycles/kernel/camera/projection.h``: ``direction_to_equirectangular`` with range
(-2 pi, pi, -pi, pi), v = 0 at the image's bottom row), and rendered: a synthetic HDRI with one
bright spot where Cycles puts a known direction is seen at the centre of a camera looking that way."""
import cv2
import numpy as np
import pytest

from scenegen.geometry.conventions import BLENDER_ENVMAP_ROTATION_Z_DEG, envmap_direction
from scenegen.spec import parse_spec, resolve_views


def cycles_uv(d):
    """Cycles' direction_to_equirectangular_range(d, (-2 pi, pi, -pi, pi)), transliterated: (u, v)
    with v = 0 at the bottom row (Blender's images are stored bottom-up)."""
    d = np.asarray(d, np.float64) / np.linalg.norm(d, axis=-1, keepdims=True)
    u = (np.arctan2(d[..., 1], d[..., 0]) - np.pi) / (-2 * np.pi)
    v = (np.arccos(d[..., 2]) - np.pi) / (-np.pi)
    return u, v


def test_blender_rotation_maps_every_texel_as_cycles_does():
    rng = np.random.default_rng(0)
    d = rng.normal(size=(2000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    u, v_bottom_up = cycles_uv(d)
    got = envmap_direction(u, 1.0 - v_bottom_up, BLENDER_ENVMAP_ROTATION_Z_DEG)  # ours: v = 0 at the top row
    np.testing.assert_allclose(got, d, atol=1e-12)
    assert np.abs(envmap_direction(u, 1.0 - v_bottom_up, 0.0) - d).max() > 0.5  # without it: turned


DIRECTION = np.array([0.62, 0.45, 0.25])  # not on an axis: a mirror or a wrong sense moves it


def spot_map(W=256, H=128) -> np.ndarray:
    """(H, W, 3) float32: radiance 0.05 everywhere, 200 in a 5x5-texel spot where Cycles puts
    DIRECTION (row 0 is the top row)."""
    u, v = cycles_uv(DIRECTION)
    col, row = int(u * W), int((1.0 - v) * H)
    img = np.full((H, W, 3), 0.05, np.float32)
    img[row - 2:row + 3, col - 2:col + 3] = 200.0
    return img


@pytest.mark.render
@pytest.mark.parametrize("fmt", ["hdr", "exr"])
def test_a_polyhaven_style_hdri_shows_its_spot_where_blender_does(tmp_path, fmt):
    from scenegen.dataset import codecs as sio
    from scenegen.render.backend import load_mitsuba

    load_mitsuba("llvm_ad_rgb")
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    img = spot_map()
    if fmt == "exr":
        sio.write_exr(tmp_path / "sky.exr", sio.pack_channels("", img, ("R", "G", "B")))
    else:
        assert cv2.imwrite(str(tmp_path / "sky.hdr"), img[..., ::-1])
    centres = {}
    for rot in (BLENDER_ENVMAP_ROTATION_Z_DEG, 0.0):
        spec = parse_spec(f"""
name: sky
lights:
  - {{type: envmap, path: sky.{fmt}, rotation_z_deg: {rot}}}
cameras:
  cam: {{size: [32, 24], fov_deg: 40}}
views:
  - camera: cam
    look_at: [{{eye: [0, 0, 0], target: {DIRECTION.tolist()}, up: [0, 0, 1]}}]
""", file=str(tmp_path / "sky.yaml"), base_dir=tmp_path)
        built = build_scene(spec, spp=4, sampler="ldsampler", max_depth=2)
        rgb = render_view(built.device, "cam", resolve_views(spec)[0].cam_from_world, spp=4, seed=0)
        lum = rgb.mean(axis=2)
        row, col = np.unravel_index(np.argmax(lum), lum.shape)
        centres[rot] = (col, row, lum.max())
    col, row, peak = centres[BLENDER_ENVMAP_ROTATION_Z_DEG]
    # the spot (5 texels = 7 deg, ~5 px) is centred within a pixel of the image centre (15.5, 11.5)
    assert abs(col - 15.5) <= 1.5 and abs(row - 11.5) <= 1.5 and peak > 20, centres
    assert centres[0.0][2] < 1.0, centres  # unturned, the spot is 90 degrees away: out of view
