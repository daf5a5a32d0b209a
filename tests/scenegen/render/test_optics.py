"""Lens and time effects (issue 4): each image effect against its exact geometry, truth unblurred."""
import math

import cv2
import numpy as np
import pytest

from scenegen.geometry.optics import Motion, Shutter, cam_from_world_at, row_poses
from scenegen.geometry.pose import look_at
from scenegen.spec import parse_spec, resolve_views

# Disk blur radius from the line-spread function's second moment: within the 10 %.
TOL_DEFOCUS_REL = 0.10
# Checkerboard corners under a rolling shutter: the bound.
TOL_ROLLING_PX = 0.2
# Per-channel corners under chromatic aberration: the bound.
TOL_CHROMATIC_PX = 0.1
# Centroid of a 20 px motion-blur streak vs the mid-exposure projection: the Monte Carlo noise of
# the time integral moves it by up to +-0.1 px across seeds and samplers (measured, 256-1024 spp);
# a truth at the start or end of the exposure would be 10 px away.
TOL_STREAK_CENTROID_PX = 0.2
# See tests/test_render.py: cornerSubPix's pixel-locking bias, removed by a symmetric blur.
DETECTOR_BLUR_SIGMA_PX = 1.0


@pytest.fixture(scope="module")
def mi():
    from scenegen.render.backend import load_mitsuba

    return load_mitsuba("llvm_ad_rgb")


def _build(text, spp=64):
    from scenegen.render.scene import build_scene

    spec = parse_spec(text)
    return spec, resolve_views(spec), build_scene(spec, spp=spp, sampler="ldsampler", max_depth=2)


STEP_SPEC = """
name: step
objects:
  - name: dark
    shape: {type: plane, size: [10, 10]}
    transform: {translation: [-5.0, 0, 0]}
    material: {type: diffuse, color: 0.05}
  - name: bright
    shape: {type: plane, size: [10, 10]}
    transform: {translation: [5.0, 0, 0]}
    material: {type: diffuse, color: 0.8}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam:
    size: [160, 120]
    fx: 800
    lens: {f_number: 1.4, focus_distance_m: 1.0, pixel_pitch_um: 30}
views:
  - camera: cam
    look_at:
      - {eye: [0.0, 0, DEPTH], target: [0.0, 0, 0], up: [0, 1, 0]}
"""


@pytest.mark.render
@pytest.mark.parametrize("depth_m", [0.5, 0.7, 1.0, 2.0, 4.0])
def test_defocus_blur_radius_follows_thin_lens(mi, depth_m):
    """A vertical step edge at depth Z blurs into a disk of radius fx A |1/Z_f - 1/Z| px."""
    from scenegen.render.frames import render_view

    spec, views, built = _build(STEP_SPEC.replace("DEPTH", str(depth_m)), spp=256)
    cam, optics = built.cameras["cam"], built.optics["cam"]
    img = render_view(built.device, "cam", views[0].cam_from_world, spp=256, seed=3).mean(axis=2)
    profile = img[20:100].mean(axis=0)  # (W,) averaged over rows
    profile = (profile - profile[:10].mean()) / (profile[-10:].mean() - profile[:10].mean())
    lsf = np.diff(profile)  # line-spread function at u + 0.5
    x = np.arange(len(lsf)) + 0.5
    centre = (lsf * x).sum() / lsf.sum()
    r_predicted = float(optics.lens.blur_radius_px(cam, depth_m))
    win = np.abs(x - centre) <= r_predicted + 4  # the LSF's support, plus the pixel; no noise tails
    lsf, x = lsf[win], x[win]
    centre = (lsf * x).sum() / lsf.sum()
    var = (lsf * (x - centre) ** 2).sum() / lsf.sum()
    # a uniform disk of radius R has an LSF variance R^2 / 4; the pixel's box adds 1 / 12
    r_measured = 2.0 * math.sqrt(max(var - 1.0 / 12.0, 0.0))
    print(f"Z = {depth_m} m: blur radius measured {r_measured:.3f} px, thin lens {r_predicted:.3f} px")
    assert abs(centre - cam.cx) < 0.05  # the edge stays where the pinhole truth puts it
    if r_predicted == 0.0:
        assert r_measured < 0.3
    else:
        assert abs(r_measured / r_predicted - 1.0) < TOL_DEFOCUS_REL, (r_measured, r_predicted)


BOARD = """
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
    dist: [-0.2, 0.05, 0.0008, -0.0006, 0.0]
    EXTRA
views:
  - camera: cam
    MOTION
    look_at:
      - {eye: [0.05, -0.12, 0.45], target: [0.0, 0.0, 0.0], up: [0, 1, 0]}
"""


def _corners(grey_linear, pattern=(9, 6)):
    from scenegen.geometry.color import srgb_image as encode_image

    img8 = encode_image(np.repeat(grey_linear[..., None], 3, axis=2), 8)[..., 0]
    found, corners = cv2.findChessboardCorners(img8, pattern)
    assert found
    smooth = cv2.GaussianBlur(grey_linear.astype(np.float32), (0, 0), DETECTOR_BLUR_SIGMA_PX)
    return cv2.cornerSubPix(smooth, corners, (7, 7), (-1, -1),
                            (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-5))[:, 0]


def _match_error(detected, truth):
    d = np.linalg.norm(detected[:, None, :] - truth[None, :, :], axis=2)
    assert len(set(d.argmin(axis=1))) == len(truth)
    return d.min(axis=1)


@pytest.mark.render
def test_rolling_shutter_corners_match_per_row_truth(mi):
    from scenegen.render.frames import render_view
    from scenegen.render.truth import truth_pass

    text = (BOARD.replace("EXTRA", "shutter: {rolling_readout_s: 0.03}")
            .replace("MOTION", "motion: {linear_velocity_mps: [1.0, 0.2, 0.0], angular_velocity_deg_s: [0, 0, 20]}"))
    spec, views, built = _build(text)
    view = views[0]
    cam = built.cameras["cam"]
    board, world_from_board = built.boards["board"]
    shutter = built.optics["cam"].shutter
    img = render_view(built.device, "cam", view.cam_from_world, spp=64, seed=1, motion=view.motion)
    detected = _corners(img.mean(axis=2))
    pts = world_from_board.apply(board.points_board)

    def project_at_row(P):
        """The row v whose pose sees P at row v: fixed point v = project(pose(t(v)), P).v."""
        v = np.full(len(P), (cam.height - 1) / 2)
        for _ in range(20):
            uv = np.array([cam.project(cam_from_world_at(view.cam_from_world, view.motion,
                                                         float(shutter.row_time_s(vi, cam.height))).apply(p[None]))[0]
                           for vi, p in zip(v, P)])
            v = uv[:, 1]
        return uv

    truth_rs = project_at_row(pts)
    truth_global = cam.project(view.cam_from_world.apply(pts))
    err = _match_error(detected, truth_rs)
    print(f"rolling shutter: corner error max {err.max():.3f} px; global-shutter truth would be off by "
          f"{np.abs(truth_rs - truth_global).max():.1f} px")
    assert err.max() < TOL_ROLLING_PX, err.max()
    assert np.abs(truth_rs - truth_global).max() > 3.0  # the effect is real and large
    # the truth pass uses each row's pose: its points reproject to their own pixels with that pose
    rows = row_poses(view.cam_from_world, view.motion, shutter, cam.height)
    truth = truth_pass(built.scene, cam, view.cam_from_world, built.id_tables, row_poses=rows)
    ys, xs = np.nonzero(truth["valid"])
    sel = np.random.default_rng(0).choice(len(ys), 200, replace=False)
    for y, x in zip(ys[sel], xs[sel]):
        uv = cam.project(rows[y].apply(truth["points_world"][y, x][None].astype(np.float64)))[0]
        assert abs(uv[0] - x) < 2e-3 and abs(uv[1] - y) < 2e-3
    # and the board's corner pixels carry the board's points
    for (u, vv), P in zip(truth_rs, pts):
        got = truth["points_world"][int(round(vv)), int(round(u))]
        assert np.linalg.norm(got - P) < 0.002  # within a pixel's footprint (~0.7 mm) of the corner


@pytest.mark.render
def test_chromatic_aberration_moves_each_channel_as_configured(mi):
    from scenegen.render.frames import render_view

    text = BOARD.replace("EXTRA", "chromatic_aberration: {red_focal_scale: 1.012, blue_focal_scale: 0.99}").replace("MOTION", "")
    spec, views, built = _build(text)
    view = views[0]
    board, world_from_board = built.boards["board"]
    cams = built.optics["cam"].chromatic_aberration.channel_cameras(built.cameras["cam"])
    img = render_view(built.device, "cam", view.cam_from_world, spp=64, seed=1)
    pts_cam = view.cam_from_world.apply(world_from_board.apply(board.points_board))
    green = cams[1].project(pts_cam)
    for c in (0, 1, 2):
        truth = cams[c].project(pts_cam)
        err = _match_error(_corners(img[..., c]), truth)
        print(f"chromatic aberration, channel {'RGB'[c]}: corner error max {err.max():.3f} px, "
              f"displacement from green up to {np.abs(truth - green).max():.2f} px")
        assert err.max() < TOL_CHROMATIC_PX, (c, err.max())
        if c != 1:
            assert np.abs(truth - green).max() > 1.5  # displaced as configured, not a no-op


SPHERE = """
name: streak
objects:
  - name: dot
    shape: {type: sphere, radius: 0.003}
    transform: {translation: [0.0, 0.0, 0.0]}
    material: {type: diffuse, color: 0.9}
    OBJMOTION
lights:
  - {type: point, position: [0, 0, 1.0], intensity: 1.0}
cameras:
  cam:
    size: [200, 120]
    fx: 500
    cx: 97.3
    cy: 61.8
    shutter: {exposure_s: 0.02}
views:
  - camera: cam
    CAMMOTION
    look_at:
      - {eye: [0.0, 0, 1.0], target: [0.0, 0, 0], up: [0, 1, 0]}
"""


@pytest.mark.render
@pytest.mark.parametrize("who", ["camera", "object"])
def test_motion_blur_streak_is_centred_at_mid_exposure(mi, who):
    """A glowing dot smeared by camera or object motion: centroid at the mid-exposure projection
    (where the truth is cast), length v T f / Z."""
    from scenegen.render.frames import render_view
    from scenegen.render.truth import truth_pass

    v_mps = 2.0  # 2 m/s over 20 ms = 4 cm = 20 px at Z = 1 m, f = 500
    cam_m = f"motion: {{linear_velocity_mps: [{-v_mps}, 0, 0]}}" if who == "camera" else ""
    obj_m = f"motion: {{linear_velocity_mps: [{v_mps}, 0, 0]}}" if who == "object" else ""
    text = SPHERE.replace("CAMMOTION", cam_m).replace("OBJMOTION", obj_m)
    spec, views, built = _build(text, spp=256)
    view = views[0]
    cam = built.cameras["cam"]
    mid = cam.project(view.cam_from_world.apply([[0.0, 0.0, 0.0]]))[0]
    img = render_view(built.device, "cam", view.cam_from_world, spp=256, seed=2, motion=view.motion).mean(axis=2)
    prof = img.sum(axis=0)
    cols = np.arange(len(prof))
    centroid_u = (prof * cols).sum() / prof.sum()
    rows = img.sum(axis=1)
    centroid_v = (rows * np.arange(len(rows))).sum() / rows.sum()
    assert abs(centroid_u - mid[0]) < TOL_STREAK_CENTROID_PX and abs(centroid_v - mid[1]) < TOL_STREAK_CENTROID_PX
    # streak length: a uniform streak of length L has a second moment L^2 / 12, plus the dot's own
    # (a disk of radius r: r^2 / 4) and the pixel's (1 / 12)
    var = (prof * (cols - centroid_u) ** 2).sum() / prof.sum()
    r_dot_px = cam.fx * 0.003 / 1.0
    length = math.sqrt(12 * (var - r_dot_px**2 / 4 - 1 / 12))
    expected = v_mps * 0.02 * cam.fx / 1.0
    print(f"{who} motion: streak centroid off by ({centroid_u - mid[0]:.3f}, {centroid_v - mid[1]:.3f}) px, "
          f"length {length:.2f} px vs v T f / Z = {expected:.2f} px")
    assert abs(length / expected - 1) < 0.05, (length, expected)
    truth = truth_pass(built.scene, cam, view.cam_from_world, built.id_tables)  # objects back at mid-exposure
    u, v = int(round(mid[0])), int(round(mid[1]))
    assert truth["object_id"][v, u] == 1


def test_row_poses_middle_row_is_the_view_pose():
    pose = look_at([1, 2, 3], [0, 0, 0]).inverse()
    rows = row_poses(pose, Motion(linear_velocity_mps=(1, 0, 0)), Shutter(rolling_readout_s=0.01), 5)
    assert rows[2].allclose(pose, atol=1e-15)
    # row 0 is 5 ms earlier: the camera was 5 mm behind along its own +x
    np.testing.assert_allclose(rows[0].inverse().t - pose.inverse().t, pose.inverse().R @ [-0.005, 0, 0], atol=1e-15)
