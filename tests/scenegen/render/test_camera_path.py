"""A camera on a trajectory within one frame (issue 16): the renderer's sensor turns and shifts
every ray by the trajectory's own displacement at the sample's time (the exposure slot plus the
row's readout offset), and the per-row truth poses are the trajectory's. Checked ray by ray
against the keyframed spline evaluated in numpy, where the tangent (constant velocity) would be
measurably off."""
import numpy as np
import pytest

from scenegen.geometry.camera import Camera
from scenegen.geometry.optics import Optics, PathMotion, Shutter, row_poses
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.geometry.trajectory import KeyframeTrajectory

pytestmark = pytest.mark.render

CAM = Camera(model="opencv", width=64, height=48, fx=60.0, fy=61.0, cx=31.5, cy=23.5,
             dist=(-0.1, 0.02, 0.001, 0.0))
SHUTTER = Shutter(exposure_s=0.01, rolling_readout_s=0.03)
# a sharp turn: ~50 m/s^2 and 300 deg/s^2 around the frame at 0.05 s
TRAJ = KeyframeTrajectory([0.0, 0.05, 0.1], [look_at([-0.1, -2, 1], [0, 0, 0]),
                                              look_at([0.05, -1.95, 1.05], [0.05, 0, 0.02]),
                                              look_at([-0.05, -2, 1.0], [0, 0, 0])], "spline")
TIME_S = 0.05
TOL_DIR = 2e-6  # rad: float32 rays and the table's interpolation, 129 nodes (measured 6.3e-7)
TOL_ORIGIN_M = 5e-6  # m: float32 origins ~2 m from the world origin, the float32 table (measured 2.2e-6)


@pytest.fixture(scope="module")
def sensor():
    from scenegen.render import load_mitsuba

    load_mitsuba("auto")
    import mitsuba as mi

    from scenegen.render import sensor as S

    S.register()
    scene = mi.load_dict({"type": "scene", "sensor": S.sensor_dict(CAM, spp=4, timed=True)})
    return scene.sensors()[0]


def test_sensor_rays_follow_the_trajectory(sensor):
    import drjit as dr
    import mitsuba as mi

    motion = PathMotion(trajectory=TRAJ, time_s=TIME_S)
    mid = motion.world_from_cam(0.0)
    sensor.set_camera(CAM, mid.inverse(), Optics(shutter=SHUTTER), motion, time_window=(0.25, 0.5))
    rng = np.random.default_rng(3)
    n = 400
    film = rng.random((n, 2))
    slot = rng.random(n)
    ray, _ = sensor.sample_ray(mi.Float(slot), mi.Float(0.5), mi.Point2f(film[:, 0], film[:, 1]),
                               mi.Point2f(0.5, 0.5))
    dr.eval(ray)
    o, d = np.array(ray.o).T.astype(np.float64), np.array(ray.d).T.astype(np.float64)
    if o.shape[0] == 3:  # (3, N) in some Dr.Jit versions
        o, d = o.T, d.T
    u, v = film[:, 0] * CAM.width - 0.5, film[:, 1] * CAM.height - 0.5
    tau = (0.25 + slot * 0.25 - 0.5) * SHUTTER.exposure_s + SHUTTER.row_time_s(v, CAM.height)
    d_cam = CAM.unproject_unit(np.stack([u, v], 1))
    worst_d = worst_o = worst_tangent = 0.0
    w = TRAJ.state(TIME_S)
    for i in range(n):
        exact = motion.world_from_cam(tau[i])
        worst_d = max(worst_d, np.linalg.norm(d[i] - exact.rotate(d_cam[i])))
        worst_o = max(worst_o, np.linalg.norm(o[i] - exact.t))
        tangent_c = mid.t + w.linear_velocity_mps * tau[i]  # what a constant velocity would give
        worst_tangent = max(worst_tangent, np.linalg.norm(tangent_c - exact.t))
    print(f"rays vs the trajectory: directions {worst_d:.1e} rad, origins {worst_o:.1e} m; "
          f"the tangent would be {worst_tangent:.1e} m off")
    assert worst_d < TOL_DIR and worst_o < TOL_ORIGIN_M
    assert worst_tangent > 100 * TOL_ORIGIN_M


def test_per_row_truth_poses_are_the_trajectory():
    motion = PathMotion(trajectory=TRAJ, time_s=TIME_S)
    mid = motion.world_from_cam(0.0).inverse()
    rows = row_poses(mid, motion, SHUTTER, CAM.height)
    for v in (0, 17, CAM.height - 1):
        want = TRAJ.pose(TIME_S + float(SHUTTER.row_time_s(v, CAM.height))).inverse()
        assert rows[v].allclose(want, 1e-12)
    assert isinstance(mid, Rigid3)
