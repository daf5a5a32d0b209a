"""The projector emitter's radiometry (scenegen.render.projector, the law stated in
scenegen.spec.sensors.projector): a projector showing white and black on a Lambertian plane, no
other light, direct lighting only. Each pixel's linear radiance must be
``rho / pi * I * (black_level + (1 - black_level) * p ** gamma) * cos(alpha) ** k * cos(theta) / d^2``
at the surface it images.

The bound (no Monte Carlo noise beyond the pixel footprint): with one delta emitter and one plane
the estimate of a sample is the law at the point its ray hits, exactly up to float32; the pixel's
value is the mean over its samples, all within the pixel's square. The law is smooth and monotone
across a pixel this small, so the mean lies within the range of the law over the pixel's four
corners (cast onto the plane here through the camera model); the bound of a pixel is that
range's largest distance from the value at its centre, plus float32 rounding (1e-5 relative)."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen.dataset import Dataset
from scenegen.dataset.codecs.exr import read_exr, unpack_channels
from scenegen.dataset.truth import LINEAR_CHANNELS
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3
from scenegen.pipeline.run import render_spec

pytestmark = pytest.mark.render

RHO = 0.5
INTENSITY = np.array([1.0, 0.5, 0.25])
BLACK = 0.1
PLANE = f"""
seed: 3
render: {{spp: 4, max_depth: 2, sampler: ldsampler}}
cameras:
  cam: {{model: pinhole, size: [48, 36], fx: 110, cx: 23.5, cy: 17.5}}
projectors:
  flat:
    intrinsics: {{model: pinhole, size: [4, 3], fx: 9.0, fy: 9.3, cx: 1.6, cy: 1.1}}
    intensity_w_sr: {INTENSITY.tolist()}
    black_level: {BLACK}
    gamma: 2.2
    pattern_axes: columns
    linear_patterns: true
  lens:
    intrinsics: {{model: pinhole, size: [4, 3], fx: 9.0, fy: 9.3, cx: 1.6, cy: 1.1}}
    intensity_w_sr: {INTENSITY.tolist()}
    falloff: cos4
    pattern_axes: columns
    linear_patterns: true
rigs:
  a: {{type: multi, members: [{{camera: cam}}, {{kind: projector, sensor: flat,
      rig_from_sensor: {{translation: [0.3, 0.05, 0.1], rotation_deg: [3, -20, 0]}}}}]}}
  b: {{type: multi, members: [{{camera: cam}}, {{kind: projector, sensor: lens,
      rig_from_sensor: {{translation: [0.3, 0.05, 0.1], rotation_deg: [3, -20, 0]}}}}]}}
objects:
  - {{name: plane, shape: {{type: plane, size: [6, 6]}}, material: {{type: diffuse, color: {RHO}}}}}
views:
  - {{rig: a, look_at: [{{eye: [0.1, -0.5, 0.9], target: [0, 0, 0]}}]}}
  - {{rig: b, look_at: [{{eye: [0.1, -0.5, 0.9], target: [0, 0, 0]}}]}}
"""


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("radiometry")
    (root / "plane.yaml").write_text(PLANE)
    render_spec(root / "plane.yaml", root / "out", progress=False)
    return Dataset(root / "out")


def law(P, center, proj_from_world: Rigid3, k: int) -> np.ndarray:
    """(..., 3) radiance of the plane z = 0 (normal +z) at world points P (..., 3) for a white
    pixel of relative output 1: rho / pi * I * cos(alpha)^k * cos(theta) / d^2."""
    v = center - P
    d = np.linalg.norm(v, axis=-1)
    cos_theta = v[..., 2] / d
    Xp = proj_from_world.apply(P.reshape(-1, 3)).reshape(P.shape)
    cos_alpha = Xp[..., 2] / np.linalg.norm(Xp, axis=-1)
    return RHO / np.pi * INTENSITY * (cos_alpha ** k * cos_theta / d ** 2)[..., None]


def on_plane(camera: Camera, cam_from_world: Rigid3, uv) -> np.ndarray:
    """World points on z = 0 seen through pixel positions uv (N, 2)."""
    world_from_cam = cam_from_world.inverse()
    rays = camera.unproject_unit(uv) @ world_from_cam.R.T
    C = world_from_cam.t
    return C + rays * (-C[2] / rays[:, 2])[:, None]


@pytest.mark.parametrize("view_set, k, black", [(0, 0, BLACK), (1, 4, 0.0)])
def test_white_and_black_on_a_lambertian_plane_follow_the_stated_law(dataset, view_set, k, black):
    view = dataset.views[view_set]
    camera, cam_from_world = dataset.camera(view)
    seq = dataset.pattern_sequence(view)
    proj = Camera.from_dict(seq["projector"]["camera"])
    proj_from_world = Rigid3.from_matrix(np.array(seq["projector"]["projector_from_world"]))
    center = proj_from_world.inverse().t
    names = [e["name"] for e in seq["patterns"]]
    linear = lambda k: unpack_channels(read_exr(dataset.path(seq["patterns"][k]["linear"])), "",
                                       LINEAR_CHANNELS).astype(np.float64)
    assert names[:2] == ["white", "black"]
    white = linear(0)
    assert np.array_equal(white, dataset.linear_image(view))  # the view's own image is pattern 0's
    P = dataset.points_world(view).astype(np.float64)
    H, W = P.shape[:2]
    centre_law = law(P, center, proj_from_world, k)
    # the law over each pixel's four corners; pixels whose corners all fall inside the projector image
    u, v = np.meshgrid(np.arange(W + 1) - 0.5, np.arange(H + 1) - 0.5)
    corners = on_plane(camera, cam_from_world, np.stack([u.ravel(), v.ravel()], 1)).reshape(H + 1, W + 1, 3)
    corner_law = law(corners, center, proj_from_world, k)
    cuv = proj.project(proj_from_world.apply(corners.reshape(-1, 3))).reshape(H + 1, W + 1, 2)
    inside_c = (cuv[..., 0] >= -0.5) & (cuv[..., 0] < proj.width - 0.5) & (cuv[..., 1] >= -0.5) & \
        (cuv[..., 1] < proj.height - 0.5)
    quad = lambda a: np.stack([a[:-1, :-1], a[:-1, 1:], a[1:, :-1], a[1:, 1:]])
    inside = quad(inside_c).all(axis=0)
    bound = np.abs(quad(corner_law) - centre_law).max(axis=0) + 1e-5 * centre_law
    assert inside.sum() > 300 and (~inside).sum() > 50  # the projector's image edge crosses the view
    err = np.abs(white - centre_law)
    assert (err[inside] <= bound[inside]).all(), (err / bound)[inside].max()
    assert np.median((bound / centre_law)[inside]) < 0.02  # not vacuous: a law off by 2 % fails
    assert (white[~quad(inside_c).any(axis=0)] == 0).all()  # outside the projector image: no light
    # the black pattern: the black level's fraction of the same law, within the same bound
    black_img = linear(1)
    assert (np.abs(black_img - black * centre_law)[inside] <= black * bound[inside] + 1e-12).all()
    assert (black_img[~quad(inside_c).any(axis=0)] == 0).all()

