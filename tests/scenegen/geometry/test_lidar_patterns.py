"""LiDAR scan patterns and the return model (scenegen.geometry.lidar) against closed forms."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen.geometry.lidar import (
    beam_directions,
    dot3,
    footprint_directions,
    footprint_offsets,
    raster_pattern,
    return_intensity,
    rotate3,
    select_returns,
    spinning_pattern,
)
from scenegen.geometry.lidar_presets import LIDAR_PRESETS


def test_a_spinning_head_fires_each_channel_at_its_offset_and_keeps_turning():
    p = spinning_pattern(elevations_deg=[-2, 0, 2], azimuth_offsets_deg=[1, 0, -1], firing_offsets_s=[0, 1e-5, 2e-5],
                         columns=100, rate_hz=20, clockwise=False, start_azimuth_deg=10)
    assert p.shape == (100, 3) and p.duration_s == 0.05
    t = np.arange(100)[:, None] / 2000.0 + np.array([0, 1e-5, 2e-5])
    assert np.allclose(p.beam_time_s, t, atol=1e-16) and np.array_equal(p.sample_time_s, p.beam_time_s[:, 0])
    az = np.radians(10 + np.array([1, 0, -1])) + 2 * np.pi * 20 * t  # counter-clockwise
    assert np.abs(np.angle(np.exp(1j * (p.azimuth_rad - az)))).max() < 1e-12
    assert np.array_equal(p.rings(), [0, 1, 2])
    with pytest.raises(ValueError, match="firing offsets must lie in"):
        spinning_pattern(elevations_deg=[0], azimuth_offsets_deg=[0], firing_offsets_s=[1e-3], columns=100, rate_hz=20)


def test_the_vlp16_rings_follow_its_interleaved_laser_table():
    el = LIDAR_PRESETS["velodyne_vlp16"]["elevations_deg"]
    p = spinning_pattern(elevations_deg=el, azimuth_offsets_deg=[0] * 16, firing_offsets_s=[0] * 16, columns=4,
                         rate_hz=10)
    assert np.array_equal(np.asarray(el)[np.argsort(p.rings())], np.arange(-15, 16, 2))


def test_a_raster_scans_lines_top_down_and_points_left_to_right_evenly_in_time():
    p = raster_pattern(fov_h_deg=60, fov_v_deg=20, rows=5, columns=7, rate_hz=10)
    assert p.shape == (5, 7)
    assert np.allclose(np.diff(p.beam_time_s.reshape(-1)), 0.1 / 35)
    assert np.isclose(p.azimuth_rad[0, 0], np.radians(30)) and np.isclose(p.azimuth_rad[0, -1], np.radians(-30))
    assert np.isclose(p.elevation_rad[0, 0], np.radians(10)) and np.isclose(p.elevation_rad[-1, 0], np.radians(-10))
    d = p.directions()
    assert np.allclose(np.linalg.norm(d, axis=-1), 1) and np.allclose(d[2, 3], [1, 0, 0])


def test_footprint_rays_lie_on_the_divergence_cone_about_each_axis():
    rng = np.random.default_rng(3)
    axes = beam_directions(rng.uniform(-np.pi, np.pi, 50), rng.uniform(-1.2, 1.2, 50))
    off = footprint_offsets(3e-3, 7)
    rays = footprint_directions(axes, off)
    assert rays.shape == (50, 7, 3) and np.array_equal(rays[:, 0], axes)
    cosang = np.einsum("nfi,ni->nf", rays[:, 1:], axes)
    assert np.allclose(np.arccos(np.clip(cosang, -1, 1)), 1.5e-3, atol=1e-9)
    assert np.allclose(np.linalg.norm(rays, axis=2), 1)


def test_first_strongest_and_last_returns_and_the_intensity_model():
    rng_m = np.array([[10.0, 12.0, np.inf], [5.0, 5.0, 5.0], [np.inf, np.inf, np.inf]])
    rho = np.array([[0.2, 0.9, 0.5], [0.5, 0.5, 0.5], [0.5, 0.5, 0.5]])
    cos = np.array([[1.0, 0.5, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, 1.0]])
    inten = return_intensity(rho, cos, rng_m, 0.01)
    assert np.isclose(inten[0, 0], 0.2 * np.exp(-0.2)) and np.isclose(inten[0, 1], 0.45 * np.exp(-0.24))
    assert inten[0, 2] == 0
    r, i = select_returns(rng_m, inten, np.isfinite(rng_m))
    assert np.array_equal(r[0], [10.0, 12.0, 12.0]) and np.array_equal(r[2], [np.inf] * 3)
    assert np.array_equal(i[2], [0, 0, 0]) and np.array_equal(r[1], [5.0, 5.0, 5.0])


def test_beam_times_at_is_np_unique_of_the_sweep_times_bit_for_bit():
    """The distinct times come from the pattern's own (cached) ones; adding a start time that
    merges neighbours by rounding gives np.unique's answer all the same."""
    osx = LIDAR_PRESETS["ouster_os1_64"]
    vlp = LIDAR_PRESETS["velodyne_vlp16"]
    for preset in (osx, vlp):
        n = len(preset["elevations_deg"])
        p = spinning_pattern(elevations_deg=preset["elevations_deg"],
                             azimuth_offsets_deg=preset.get("azimuth_offsets_deg") or [0.0] * n,
                             firing_offsets_s=np.asarray(preset.get("firing_offsets_us") or [0.0] * n) * 1e-6,
                             columns=preset["columns"], rate_hz=preset["rate_hz"])
        for t0 in (0.0, 0.1, 1234.5678, 3.0e10):  # at 3e10 s neighbouring firing times round together
            want_t, want_i = np.unique(t0 + p.beam_time_s.reshape(-1), return_inverse=True)
            got_t, got_i = p.beam_times_at(t0)
            assert got_t.tobytes() == want_t.tobytes() and np.array_equal(got_i, want_i)
    assert len(np.unique(3.0e10 + p.distinct_beam_times[0])) < len(p.distinct_beam_times[0])


def test_dot3_and_rotate3_sum_in_einsums_order():
    """The rays and incidence a kernel computes have numpy's einsum bits: the sum order and the
    +0 of einsum's accumulator (signed zeros included), for a beam's axis and its footprint rays."""
    rng = np.random.default_rng(30)
    def mixed(shape):  # with exact zeros of both signs
        a = rng.standard_normal(shape)
        u = rng.random(shape)
        a[u < 0.2], a[(u >= 0.2) & (u < 0.4)] = 0.0, -0.0
        return a
    R, d, rays = mixed((20000, 3, 3)), mixed((20000, 3)), mixed((20000, 4, 3))
    got = np.stack(rotate3([[R[:, i, j] for j in range(3)] for i in range(3)], [d[:, j] for j in range(3)]), 1)
    assert got.tobytes() == np.einsum("nij,nj->ni", R, d).tobytes()
    got = np.stack(rotate3([[R[:, None, i, j] for j in range(3)] for i in range(3)], [rays[..., j] for j in range(3)]), -1)
    assert got.tobytes() == np.einsum("nij,nfj->nfi", R, rays).tobytes()
    assert dot3([rays[..., i] for i in range(3)], [rays[:, ::-1, i] for i in range(3)]).tobytes() == \
        np.einsum("nfi,nfi->nf", rays, rays[:, ::-1]).tobytes()
    assert not np.array_equal(np.signbit(R[:, 0, 0] * d[:, 0] + R[:, 0, 1] * d[:, 1] + R[:, 0, 2] * d[:, 2]),
                              np.signbit(got[:, 0, 0]))  # plain summation differs (signs of zero, order)
