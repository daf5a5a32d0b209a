"""A sweep's measurement model (scenegen.spec.sensors.lidar_sweep) on a ground plane cast in numpy:
range noise with its sigma, seeded and reproducible; dropouts by incidence, intensity and rate;
first and last returns of a footprint across a step; the pose at each beam's own time."""
from __future__ import annotations

import numpy as np

from scenegen.geometry.clock import StaticTrajectory
from scenegen.geometry.pose import Rigid3
from scenegen.spec.sensors.lidar import LidarSpec
from scenegen.spec.sensors.lidar_beams import beam_cast_by_rays
from scenegen.spec.sensors.lidar_sweep import sweep_fields

HEIGHT = 2.0  # the LiDAR above the ground plane z = 0


def ground(origins, dirs, times):
    """z = 0, normal +z, object 1; and a step z = 0.5 for x > 8 (object 2)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(dirs[:, 2] < 0, -origins[:, 2] / dirs[:, 2], np.inf)
        t_step = np.where(dirs[:, 2] < 0, (0.5 - origins[:, 2]) / dirs[:, 2], np.inf)
    on_step = np.isfinite(t_step) & (origins[:, 0] + t_step * dirs[:, 0] > 8.0)
    r = np.where(on_step, t_step, t)
    oid = np.where(np.isfinite(r), np.where(on_step, 2, 1), 0).astype(np.uint32)
    n = np.tile([0.0, 0.0, 1.0], (len(r), 1))
    return r, n, oid, oid.copy()


def lidar(**kw):
    base = dict(name="l", elevations_deg=(-30.0, -20.0, -10.0, -5.0), columns=360, rate_hz=10.0, max_range_m=200.0)
    return LidarSpec(**{**base, **kw})


POSE = StaticTrajectory(Rigid3(np.eye(3), np.array([0.0, 0.0, HEIGHT])))


def sweep(spec, key=(1, "s", 0), traj=POSE):
    return sweep_fields(beam_cast_by_rays(ground), spec, spec.scan_pattern(), traj, 0.0, reflectivity={2: 0.2}, noise_key=key)


def test_truth_is_the_closed_form_and_noise_has_its_sigma_and_seed():
    f = sweep(lidar(range_noise_m=0.02))
    el = f["elevation_rad"]
    plane = f["object_id"] == 1
    assert np.allclose(f["range_m"][plane], HEIGHT / np.sin(-el[plane]), rtol=1e-12)
    assert np.allclose(f["incidence_rad"][plane], np.pi / 2 + el[plane], atol=1e-9)
    err = f["measured_range_m"] - f["range_m"]
    assert 0.018 < np.std(err) < 0.022 and abs(np.mean(err)) < 0.002
    again = sweep(lidar(range_noise_m=0.02))
    assert all(np.array_equal(f[k], again[k], equal_nan=True) for k in f)
    other = sweep(lidar(range_noise_m=0.02), key=(1, "s", 1))
    assert not np.array_equal(f["measured_range_m"], other["measured_range_m"])


def test_dropouts_by_incidence_intensity_and_rate():
    f = sweep(lidar(max_incidence_deg=75.0))  # the -10 and -5 degree beams meet the ground at 80 and 85 degrees
    assert np.all(f["dropped"][:, 2:][f["object_id"][:, 2:] == 1]) and not f["dropped"][:, :2].any()
    assert np.all(np.isnan(f["measured_range_m"][f["dropped"]]))
    # the step (reflectivity 0.2) falls below min_intensity 0.15 at every incidence past acos(0.75)
    f = sweep(lidar(min_intensity=0.15))
    step = f["object_id"] == 2
    want = 0.2 * np.cos(f["incidence_rad"][step]) < 0.15
    assert want.any() and np.array_equal(f["dropped"][step], want)
    f = sweep(lidar(dropout_rate=0.25))
    assert 0.2 < f["dropped"].mean() < 0.3


def test_a_footprint_across_the_step_gives_distinct_first_and_last_returns():
    spec = lidar(divergence_mrad=20.0, footprint_rays=9, return_mode="last")
    f = sweep(spec)
    r = f["returns_m"]
    edge = np.isfinite(r[..., 0]) & (r[..., 2] - r[..., 0] > 0.5)
    assert edge.any() and np.all(r[..., 0] <= r[..., 1]) and np.all(r[..., 1] <= r[..., 2])
    assert np.array_equal(f["measured_range_m"][edge], r[..., 2][edge])


def test_each_beam_is_posed_at_its_own_time():
    class Moving:  # 10 m/s along +x
        def poses_at(self, t):
            t = np.asarray(t, np.float64)
            return np.tile(np.eye(3), (len(t), 1, 1)), np.stack([10.0 * t, 0 * t, HEIGHT + 0 * t], 1)

    f = sweep(lidar(), traj=Moving())
    assert np.allclose(f["sensor_position_m"][..., 0], 10.0 * f["beam_time_s"], atol=1e-15)
    hit = f["object_id"] == 1
    assert np.allclose(f["point_world_m"][..., 0][hit],
                       10.0 * f["beam_time_s"][hit] + f["point_sensor_m"][..., 0][hit], atol=1e-12)


def test_a_raster_sweep_sees_the_ground_where_its_lines_point():
    spec = lidar(pattern="raster", fov_h_deg=60.0, fov_v_deg=20.0, rows=8, columns=16, elevations_deg=None)
    tilted = StaticTrajectory(Rigid3(np.array([[np.cos(-0.3), 0, np.sin(-0.3)], [0, 1, 0],
                                               [-np.sin(-0.3), 0, np.cos(-0.3)]]).T, np.array([0.0, 0.0, HEIGHT])))
    f = sweep(spec, traj=tilted)  # pitched down by 0.3 rad: every line meets the ground
    assert f["range_m"].shape == (8, 16) and np.isfinite(f["range_m"]).all()
    d_world = f["point_world_m"] - f["sensor_position_m"]
    assert np.allclose(f["point_world_m"][..., 2][f["object_id"] == 1], 0.0, atol=1e-12)
    assert np.allclose(np.linalg.norm(d_world, axis=-1), f["range_m"], rtol=1e-12)
    assert np.all(np.diff(f["beam_time_s"].reshape(-1)) > 0)
