"""The renderer and the truth pass against the camera model and analytic geometry."""

import numpy as np
import pytest

from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.pose import look_at
from scenegen.spec import parse_spec, resolve_views

# Centroid of a ~6 px emissive disc vs the projection of its centre: the bound.
TOL_SPHERE_CENTROID_PX = 0.05
# Reprojection of stored (float32) truth points: float32 rounding of ~3 m values at f ~ 500 px.
TOL_TRUTH_REPROJ_PX = 1e-3
# Analytic depth: Mitsuba intersects in float32 (relative ~1e-7); the bound.
TOL_ANALYTIC_REL = 1e-5
# Unit roundoff of float32: points and normals are rounded once to float32 by the truth pass.
FLOAT32_REL = 2.0**-24


@pytest.fixture(scope="module")
def mi():
    from scenegen.render.backend import load_mitsuba

    mi = load_mitsuba("llvm_ad_rgb")
    from scenegen.render import sensor

    sensor.register()
    return mi


CAMERAS = {
    "opencv_skew": Camera.from_opencv(np.array([[520.0, 4.0, 331.2], [0, 560.0, 233.7], [0, 0, 1]]),
                                      [-0.28, 0.09, 0.002, -0.001, -0.01], (640, 480)),
    "fisheye": Camera.from_opencv_fisheye(np.array([[260.0, 0, 322.5], [0, 255.0, 236.0], [0, 0, 1]]),
                                          [0.03, -0.01, 0.002, -0.0003], (640, 480)),
    "rational_prism": Camera("opencv", 640, 480, 600.0, 590.0, 318.0, 242.0, 0.0,
                             (0.1, -0.05, 0.001, 0.0005, 0.01, 0.05, -0.02, 0.01, 0.002, -0.001, 0.001, 0.0005)),
}


@pytest.mark.render
@pytest.mark.parametrize("name", list(CAMERAS))
def test_emissive_spheres_land_at_projection(mi, name):
    """Tiny emissive spheres placed on a pixel grid at random depths appear exactly there."""
    from scenegen.render import sensor as S

    cam = CAMERAS[name]
    world_from_cam = look_at([0.3, -4.0, 1.0], [0, 0, 0])
    cam_from_world = world_from_cam.inverse()
    rng = np.random.default_rng(5)
    targets = np.stack(np.meshgrid(np.linspace(40, 600, 6), np.linspace(40, 440, 5)), -1).reshape(-1, 2)
    targets += rng.uniform(-10, 10, targets.shape)
    depth = rng.uniform(2.5, 5.0, len(targets))
    rays = cam.unproject_unit(targets)
    centres_cam = rays * depth[:, None]
    centres_world = world_from_cam.apply(centres_cam)
    d = {"type": "scene", "integrator": {"type": "direct"}, "sensor": S.sensor_dict(cam, spp=64)}
    for i, (p, z) in enumerate(zip(centres_world, depth)):
        d[f"s{i}"] = {"type": "sphere", "center": p.tolist(), "radius": 0.018 * z / 4.0,
                      "emitter": {"type": "area", "radiance": {"type": "rgb", "value": 1.0}}}
    scene = mi.load_dict(d)
    sensor = scene.sensors()[0]
    sensor.set_camera(cam, cam_from_world)
    img = np.array(mi.render(scene, sensor=sensor, spp=64))[..., 0]
    errs = []
    for u, v in cam.project(centres_cam):
        u0, v0 = int(round(u)), int(round(v))
        win = img[v0 - 8:v0 + 9, u0 - 8:u0 + 9]
        vv, uu = np.mgrid[v0 - 8:v0 + 9, u0 - 8:u0 + 9]
        assert win.sum() > 1.0, "sphere not visible where the camera model projects it"
        errs.append([(win * uu).sum() / win.sum() - u, (win * vv).sum() / win.sum() - v])
    err = np.abs(np.array(errs)).max()
    assert err < TOL_SPHERE_CENTROID_PX, err


ANALYTIC_SPEC = """
name: analytic
objects:
  - name: ground
    shape: {type: plane, size: [20, 20]}
  - name: ball
    shape: {type: sphere, radius: 0.5}
    transform: {translation: [0.2, 0.1, 0.6]}
    instance_id: 9
lights:
  - type: constant
    radiance: 1
cameras:
  cam:
    model: opencv
    size: [320, 240]
    fx: 260
    fy: 250
    cx: 161.5
    cy: 118.2
    skew: 1.5
    dist: [-0.2, 0.05, 0.001, 0.0, 0.0]
views:
  - camera: cam
    look_at:
      - {eye: [2.0, -2.5, 1.8], target: [0, 0, 0.3]}
"""


@pytest.fixture(scope="module")
def analytic(mi):
    from scenegen.render.scene import build_scene
    from scenegen.render.truth import truth_pass

    spec = parse_spec(ANALYTIC_SPEC)
    view = resolve_views(spec)[0]
    built = build_scene(spec, spp=4, sampler="ldsampler", max_depth=2)
    cam = built.cameras["cam"]
    truth = truth_pass(built.scene, cam, view.cam_from_world, built.id_tables)
    return cam, view.cam_from_world, truth


def _analytic_range(cam, cam_from_world):
    """Per-pixel analytic range to the plane z = 0 and the sphere; and which is hit first."""
    world_from_cam = cam_from_world.inverse()
    d = cam.unproject_unit(pixel_centers(cam.width, cam.height).reshape(-1, 2)) @ world_from_cam.R.T
    C = world_from_cam.t
    with np.errstate(divide="ignore"):
        t_plane = np.where(d[:, 2] < 0, -C[2] / d[:, 2], np.inf)
    hit_xy = C[:2] + d[:, :2] * np.where(np.isfinite(t_plane), t_plane, 0)[:, None]
    t_plane[np.abs(hit_xy).max(axis=1) > 10.0] = np.inf  # the plane is 20 m x 20 m
    oc = C - np.array([0.2, 0.1, 0.6])
    b = d @ oc
    disc = b * b - (oc @ oc - 0.25)
    t_sphere = np.where(disc > 0, -b - np.sqrt(np.maximum(disc, 0)), np.inf)
    H, W = cam.height, cam.width
    return t_plane.reshape(H, W), t_sphere.reshape(H, W)


@pytest.mark.render
def test_truth_depth_matches_analytic_plane_and_sphere(analytic):
    cam, cam_from_world, truth = analytic
    t_plane, t_sphere = _analytic_range(cam, cam_from_world)
    t_an = np.minimum(t_plane, t_sphere)
    on_sphere = t_sphere < t_plane
    # the truth's object ids agree with the analytic first hit
    np.testing.assert_array_equal(truth["object_id"] == 2, on_sphere & np.isfinite(t_sphere))
    assert set(np.unique(truth["instance_id"][on_sphere])) == {9}
    valid = truth["valid"]
    np.testing.assert_array_equal(valid, np.isfinite(t_an))
    rel = np.abs(truth["range"][valid] / t_an[valid] - 1)
    assert rel.max() < TOL_ANALYTIC_REL, rel.max()
    assert on_sphere.sum() > 1000 and (valid & ~on_sphere).sum() > 1000


@pytest.mark.render
def test_truth_self_consistency(analytic):
    cam, cam_from_world, truth = analytic
    v = truth["valid"]
    uv = cam.project(truth["points_cam"][v].astype(np.float32).astype(np.float64))
    grid = pixel_centers(cam.width, cam.height)[v]
    assert np.abs(uv - grid).max() < TOL_TRUTH_REPROJ_PX
    # depth is z, range is the distance; consistent with each other and with the points, which
    # are rounded once to float32 (relative 2^-24 each coordinate)
    pc = truth["points_cam"][v].astype(np.float64)
    np.testing.assert_allclose(truth["depth_z"][v], pc[:, 2], rtol=FLOAT32_REL)
    np.testing.assert_allclose(truth["range"][v], np.linalg.norm(pc, axis=1), rtol=2 * FLOAT32_REL)
    assert np.all(truth["range"][v] >= truth["depth_z"][v])
    world_extent_m = np.abs(truth["points_world"][v]).max()
    np.testing.assert_allclose(cam_from_world.apply(truth["points_world"][v].astype(np.float64)), pc,
                               atol=4 * FLOAT32_REL * (world_extent_m + np.abs(pc).max()))
    # normals: unit, plane normal is +z, sphere normal radial; camera-frame normals are rotated world ones
    n = truth["normals_world"][v]
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)
    plane = truth["object_id"][v] == 1
    np.testing.assert_allclose(n[plane], np.tile([0, 0, 1.0], (plane.sum(), 1)), atol=1e-6)
    radial = truth["points_world"][v][~plane] - np.array([0.2, 0.1, 0.6])
    np.testing.assert_allclose(n[~plane], radial / np.linalg.norm(radial, axis=1, keepdims=True), atol=2e-5)
    np.testing.assert_allclose(truth["normals_cam"][v], cam_from_world.rotate(n), atol=4 * FLOAT32_REL)
    # misses follow the documented convention
    miss = ~v
    assert miss.any()
    assert np.all(np.isinf(truth["range"][miss])) and np.all(np.isinf(truth["depth_z"][miss]))
    assert np.isnan(truth["points_world"][miss]).all() and (truth["object_id"][miss] == 0).all()


BOARD_SPEC = """
name: board
objects:
  - name: board
    target: {type: checkerboard, inner_cols: 9, inner_rows: 6, square_m: 0.03}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam:
    model: opencv
    size: [640, 480]
    fx: 610
    fy: 600
    cx: 322.4
    cy: 237.1
    skew: 0.8
    dist: [-0.25, 0.07, 0.0008, -0.0006, -0.008]
views:
  - camera: cam
    look_at:
      - {eye: [0.08, -0.25, 0.42], target: [0.0, 0.0, 0.0], up: [0, 1, 0]}
      - {eye: [-0.2, 0.1, 0.45], target: [0.01, 0.0, 0.0], up: [0, 1, 0]}
"""

# cornerSubPix on a clean, anti-aliased render: the bound.
TOL_CHESSBOARD_PX = 0.1
# cornerSubPix "pixel-locks" on sharp box-filtered edges: measured +-0.075 px bias that varies
# with the corner's sub-pixel phase on a fronto-parallel board (0.095 px max), falling to
# 0.042 px after a sigma = 1 px Gaussian and 0.026 px after sigma = 1.5 px. A Gaussian is
# point-symmetric, so it cannot move an X-junction's saddle point: it only removes the detector's
# bias, which is why the test blurs before refining.
DETECTOR_BLUR_SIGMA_PX = 1.0


@pytest.mark.render
def test_chessboard_corners_detected_at_truth(mi):
    import cv2

    from scenegen.geometry.color import srgb_image as encode_image
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    spec = parse_spec(BOARD_SPEC)
    built = build_scene(spec, spp=64, sampler="ldsampler", max_depth=2)
    board, world_from_board = built.boards["board"]
    cam = built.cameras["cam"]
    for view in resolve_views(spec):
        linear = render_view(built.device, "cam", view.cam_from_world, spp=64, seed=1)
        grey = cv2.cvtColor(encode_image(linear, 8), cv2.COLOR_RGB2GRAY)
        found, corners = cv2.findChessboardCorners(grey, (9, 6))
        assert found
        smooth = cv2.GaussianBlur(cv2.cvtColor(linear, cv2.COLOR_RGB2GRAY), (0, 0), DETECTOR_BLUR_SIGMA_PX)
        corners = cv2.cornerSubPix(smooth, corners, (7, 7), (-1, -1),
                                   (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-5))[:, 0]
        truth = cam.project(view.cam_from_world.apply(world_from_board.apply(board.points_board)))
        # OpenCV may return the grid in either direction: match by nearest truth point
        d = np.linalg.norm(corners[:, None, :] - truth[None, :, :], axis=2)
        assert len(set(d.argmin(axis=1))) == len(truth)
        err = d.min(axis=1)
        print(f"{view.name}: chessboard corner error max {err.max():.3f} px, rms {np.sqrt(np.mean(err**2)):.3f} px")
        assert err.max() < TOL_CHESSBOARD_PX, err.max()


@pytest.mark.render
def test_envmap_top_row_is_world_up(mi, tmp_path):
    """The spec's convention: an equirectangular map's top row is world +z (Mitsuba's is +y)."""
    from scenegen.dataset import codecs as sio
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    env = np.zeros((32, 64, 3), np.float32)
    env[:16] = (0.1, 0.2, 0.9)  # upper half: blue sky
    env[16:] = (0.8, 0.3, 0.1)  # lower half: red ground
    sio.write_exr(tmp_path / "env.exr", sio.pack_channels("", env, ("R", "G", "B")))
    spec = parse_spec("""
name: env
lights:
  - {type: envmap, path: env.exr}
cameras:
  cam: {size: [16, 12], fov_deg: 30}
views:
  - camera: cam
    look_at:
      - {eye: [0, 0, 0], target: [0.01, 0, 1], up: [1, 0, 0]}
      - {eye: [0, 0, 0], target: [0.01, 0, -1], up: [1, 0, 0]}
      - {eye: [0, 0, 0], target: [1, 0, 0.3]}
""", file=str(tmp_path / "env.yaml"), base_dir=tmp_path)
    built = build_scene(spec, spp=16, sampler="ldsampler", max_depth=2)
    up, down, horizon = (render_view(built.device, "cam", v.cam_from_world, spp=16, seed=0)
                         for v in resolve_views(spec))
    np.testing.assert_allclose(up.mean(axis=(0, 1)), (0.1, 0.2, 0.9), atol=0.02)
    np.testing.assert_allclose(down.mean(axis=(0, 1)), (0.8, 0.3, 0.1), atol=0.02)
    # looking 17 degrees above the horizon: sky in the whole view (fov 30 deg horizontally)
    assert horizon[:3].mean(axis=(0, 1))[2] > 0.8


@pytest.mark.render
@pytest.mark.parametrize("sampler", ["ldsampler", "orthogonal", "stratified", "multijitter", "independent"])
def test_effective_spp_is_what_mitsuba_takes(mi, sampler):
    """The spec layer's rounding rule (no Mitsuba import there) against the plugin itself."""
    from scenegen.spec.model import effective_spp

    counts = list(range(1, 130)) + [255, 256, 257, 1000, 1024]
    got = [mi.load_dict({"type": sampler, "sample_count": n}).sample_count() for n in counts]
    assert [effective_spp(sampler, n) for n in counts] == got


@pytest.mark.render
def test_spp_rounding_is_stated_not_warned_and_recorded(tmp_path, capsys):
    from scenegen.cli import main
    from scenegen.pipeline.run import render_spec

    spec = ("render: {spp: 8}\nobjects: [{name: p, shape: plane}]\ncameras: {c: {size: [8, 6], fx: 8}}\n"
            "views: [{camera: c, look_at: [{eye: [0, -2, 1], target: [0, 0, 0]}]}]\n")
    s = parse_spec(spec, "s.yaml")
    assert s.warnings == ()  # the rounding is stated by validate and render, not warned about
    (tmp_path / "s.yaml").write_text(spec)
    assert main(["validate", str(tmp_path / "s.yaml")]) == 0
    out, err = capsys.readouterr()
    assert "spp 8 (the ldsampler takes 16)" in out and err == ""
    assert main(["render", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "o1"), "--spp", "1", "--no-progress"]) == 0
    out, err = capsys.readouterr()
    assert "spp 1 (sampler takes 4)" in out and "warning" not in err, err
    out = render_spec(tmp_path / "s.yaml", tmp_path / "out", progress=False)
    assert (out.settings.spp, out.settings.spp_effective) == (8, 16)
    import json

    used = json.loads((tmp_path / "out" / "cameras.json").read_text())["spec"]["render_used"]
    assert (used["spp"], used["spp_effective"]) == (8, 16)
