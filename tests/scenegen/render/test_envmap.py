"""The orientation of an environment map (scenegen.geometry.conventions.envmap_direction), EXR
and Radiance HDR files: a map whose every texel stores its own world direction as a colour
((d + 1) / 2), looked at through a narrow pinhole along many directions, shows at the centre
of each view the direction the camera looks along."""
import cv2
import numpy as np
import pytest

from scenegen.geometry.conventions import envmap_direction
from scenegen.spec import parse_spec, resolve_views

# Angle between the decoded colour and the view direction: at most one texel (360 / 256 deg):
# bilinear interpolation of the (not linear) direction field and the pixel's own footprint.
# Measured: 0.003 deg along the axes, up to 0.60 deg (EXR) and 0.68 deg (HDR, RGBE) elsewhere; a
# wrong axis, mirror or rotation sense is off by tens of degrees.
TOL_DEG = {"exr": 360 / 256, "hdr": 360 / 256}
DIRECTIONS = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0.6, -0.5, 0.62), (-0.3, 0.8, -0.52),
              (0.2, 0.1, 0.97)]


def direction_map(rotation_z_deg, H=128, W=256):
    u = (np.arange(W) + 0.5) / W
    v = (np.arange(H) + 0.5) / H
    d = envmap_direction(u[None, :], v[:, None], rotation_z_deg)
    return ((d + 1) / 2).astype(np.float32)


@pytest.mark.render
@pytest.mark.parametrize("fmt,rotation", [("exr", 0.0), ("exr", 30.0), ("hdr", -75.0)])
def test_envmap_orientation(tmp_path, fmt, rotation):
    from scenegen.dataset import codecs as sio
    from scenegen.render.backend import load_mitsuba

    load_mitsuba("llvm_ad_rgb")
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    img = direction_map(rotation)
    if fmt == "exr":
        sio.write_exr(tmp_path / "env.exr", sio.pack_channels("", img, ("R", "G", "B")))
    else:
        assert cv2.imwrite(str(tmp_path / "env.hdr"), img[..., ::-1])
    looks = "\n".join(f"      - {{eye: [0, 0, 0], target: {list(d)}, up: {[0, 1, 0] if abs(d[2]) > 0.9 else [0, 0, 1]}}}"
                      for d in DIRECTIONS)
    spec = parse_spec(f"""
name: env
lights:
  - {{type: envmap, path: env.{fmt}, rotation_z_deg: {rotation}}}
cameras:
  cam: {{model: pinhole, size: [5, 5], fx: 200, fy: 200, cx: 2, cy: 2}}
views:
  - camera: cam
    look_at:
{looks}
""", file=str(tmp_path / "env.yaml"), base_dir=tmp_path)
    built = build_scene(spec, spp=16, sampler="ldsampler", max_depth=2)
    errs = []
    for view, d in zip(resolve_views(spec), DIRECTIONS):
        rgb = render_view(built.device, "cam", view.cam_from_world, spp=16, seed=0)[2, 2].astype(np.float64)
        got = 2 * rgb - 1
        want = np.asarray(d, np.float64) / np.linalg.norm(d)
        errs.append(np.degrees(np.arccos(np.clip(got @ want / np.linalg.norm(got), -1, 1))))
    print(f"envmap {fmt} rotation {rotation}: direction error max {max(errs):.3f} deg")
    assert max(errs) < TOL_DEG[fmt], errs
