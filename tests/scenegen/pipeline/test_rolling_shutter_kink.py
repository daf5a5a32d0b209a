"""Rolling-shutter truth where a trajectory has a kink inside a frame's readout (issue 26): a
camera at 3.7 m/s and a ball on two-keyframe linear paths, frames at the first and the last
keyframe times, so that half of frame 0's rows (and of frame 3's) see the held end pose and the
other half the moving one. Flow and scene flow for the pairs 1 -> 0 and 2 -> 3 (the imaging row
found in the kinked frame) and 0 -> 1, 3 -> 2 (the points cast in it) against the test's own
derivation: clamped slerp/lerp poses evaluated directly at every ray's time, its own ray casts and
a bisection on the imaging row (tests/scenegen/pipeline/analytic_scene.py). Before the keyframes
were knots of the row tables the stored flow was off by up to 0.0145 px and the scene flow by
0.15 mm on such a path."""
import sys
from pathlib import Path

import numpy as np
import pytest

from scenegen.dataset.codecs import read_exr
from scenegen.pipeline.run import render_spec

sys.path.insert(0, str(Path(__file__).parent))
from analytic_scene import AnalyticScene, RollingPinhole, look  # noqa: E402

pytestmark = [pytest.mark.render, pytest.mark.filterwarnings("ignore:invalid value:RuntimeWarning"),
              pytest.mark.filterwarnings("ignore:divide by zero:RuntimeWarning")]

W, H, F = 80, 60, 70.0
TIMES = [0.0, 0.1, 0.2, 0.3]
READOUT = 0.03
TOL_FLOW_PX = 2e-4  # as tests/scenegen/pipeline/test_rolling_shutter_truth.py (float32 storage)
TOL_SCENE_FLOW_M = 3e-6
SPEC = """
name: kink
render: {spp: 1, max_depth: 2}
sequence: {fps: 10, frames: 4, flow_steps: [1]}
objects:
  - name: floor
    shape: {type: plane, size: [4, 4]}
  - name: ball
    shape: {type: sphere, radius: 0.25}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [-0.5, 0.2, 0.25]}
        - {time_s: 0.3, translation: [0.5, -0.2, 0.35]}
lights: [{type: constant, radiance: 1}]
cameras: {cam: {size: [80, 60], fx: 70, shutter: {rolling_readout_s: 0.03}}}
views:
  - camera: cam
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0.55, -1.9, 1.2], target: [0, 0, 0.1]}
        - {time_s: 0.3, eye: [-0.55, -1.7, 1.3], target: [0, 0.05, 0.1]}
"""
SCENE = AnalyticScene(paths={"ball": (0.0, 0.3, np.eye(3), np.eye(3), [-0.5, 0.2, 0.25], [0.5, -0.2, 0.35])},
                      ids={"floor": 1, "ball": 2})
CAM = RollingPinhole(W, H, F, READOUT, (0.0, 0.3, look([0.55, -1.9, 1.2], [0, 0, 0.1]),
                                        look([-0.55, -1.7, 1.3], [0, 0.05, 0.1]), [0.55, -1.9, 1.2], [-0.55, -1.7, 1.3]))


def frame_points(t_frame):
    """Per pixel: (N, 3) surface points, (N,) ids, (N,) row times."""
    return CAM.frame_points(SCENE, t_frame)[:3]


def imaged(P_a, ids, t_a, t_frame):
    """(N, 2) pixels and (N, 3) world points where frame t_frame images the points P_a (seen at
    times t_a): bisection on g(v) = row(point at time(v)) - v; NaN where no row in the frame."""
    def at(v):
        t = CAM.row_time(t_frame, v)
        P = SCENE.moved(P_a, ids, t_a, t)
        uv, z = CAM.project(P, t)
        return uv, P, np.where(z > 0, uv[:, 1] - v, np.nan)
    a, b = np.full(len(P_a), -0.5), np.full(len(P_a), H - 0.5)
    ok = (at(a)[2] > 0) & (at(b)[2] < 0)
    for _ in range(60):
        m = 0.5 * (a + b)
        g = at(m)[2]
        a, b = np.where(g > 0, m, a), np.where(g > 0, b, m)
    uv, P, _ = at(0.5 * (a + b))
    uv[~ok], P[~ok] = np.nan, np.nan
    return uv, P


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("kink")
    (root / "scene.yaml").write_text(SPEC)
    render_spec(root / "scene.yaml", root / "out", progress=False)
    return root / "out"


@pytest.mark.parametrize("ka,kb", [(1, 0), (2, 3), (0, 1), (3, 2)])
def test_flow_and_scene_flow_across_a_kink_in_the_readout(dataset, ka, kb):
    a, b = f"cam_{ka:04d}", f"cam_{kb:04d}"
    P_a, ids, t_a = frame_points(TIMES[ka])
    ours_ids = read_exr(dataset / f"truth/{a}_ids.exr")["object_id"].reshape(-1)
    uv, P_b = imaged(P_a, ids, t_a, TIMES[kb])
    ch = read_exr(dataset / f"sequence/motion/{a}/{b}.exr")
    grid = np.stack(np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float)), -1).reshape(-1, 2)
    ours = np.stack([ch["u"], ch["v"]], -1).reshape(-1, 2)
    sf = np.stack([ch[f"scene_flow.{c}"] for c in "XYZ"], -1).reshape(-1, 3)
    cmp = (ids == ours_ids) & (ids > 0) & np.isfinite(uv).all(1) & np.isfinite(ours).all(1)
    err_flow = np.abs(ours[cmp] - uv[cmp]).max()
    err_sf = np.abs(sf[cmp] - (P_b - P_a)[cmp]).max()
    print(f"{a}->{b}: {cmp.sum()} pixels, flow within {err_flow:.2e} px, scene flow within {err_sf:.2e} m")
    assert cmp.sum() > 0.5 * W * H  # most pixels: the rest leave the frame or miss the floor
    assert err_flow < TOL_FLOW_PX and err_sf < TOL_SCENE_FLOW_M
    assert np.abs((uv - grid)[cmp]).max() > 1.0  # the camera moves: the comparison is not vacuous
