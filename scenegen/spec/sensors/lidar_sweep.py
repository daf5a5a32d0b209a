"""One LiDAR sweep as stream fields: every beam posed and cast at its own firing time, then the
return model (:mod:`scenegen.geometry.lidar`), noise and dropouts.

The truth is the beam axis's exact first hit: the LiDAR at ``world_from_lidar(t)`` and every
moving object where it is at ``t``, ``t`` the beam's firing time. The measurement follows from it:
the footprint rays' returns (first, strongest, last), the selected ``return_mode``, the seeded
range noise and the dropouts. Noise and random dropouts are drawn from
``seeds.rng(*noise_key)`` (the LiDAR's seed, the stream, the sweep): the same spec gives the same
bits, and a resumed run redraws a sweep exactly.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from scenegen.geometry import seeds
from scenegen.geometry.lidar import (
    RETURN_MODES,
    ScanPattern,
    footprint_directions,
    footprint_offsets,
    return_intensity,
    select_returns,
)
from scenegen.geometry.rotation import quat_wxyz_from_matrix

#: cast(origins (N, 3), directions (N, 3) unit, times (N,) s) -> ((N,) range m, inf = none,
#: (N, 3) unit surface normals, (N,) uint32 object ids, (N,) uint32 instance ids), world frame.
Cast = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple]


def sweep_fields(cast: Cast, lidar, pattern: ScanPattern, world_from_lidar, t0_s: float, *, reflectivity=None,
                 noise_key=(0,), static_time_s: float | None = None) -> dict[str, np.ndarray]:
    """The stream fields (``scenegen.spec.sensors.lidar.FIELDS``, less ``sweep``) of the sweep
    that starts at ``t0_s`` (s); ``world_from_lidar`` a :class:`scenegen.geometry.clock.Trajectory`;
    ``reflectivity`` {object id: value} over ``lidar.reflectivity``. ``static_time_s``: cast every
    beam with the LiDAR and the objects at that one time (a "static picture" sweep, as CARLA's:
    for comparisons only; the beams keep their own times in ``beam_time_s``)."""
    M, C = pattern.shape
    times = (t0_s + pattern.beam_time_s).reshape(-1)  # (N,)
    cast_times = times if static_time_s is None else np.full_like(times, static_time_s)
    # beams that fire together share a pose: evaluated once per distinct time (exact, and a
    # spinning head's 64 channels of a column are one time)
    unique_times, at = np.unique(cast_times, return_inverse=True)
    R_u, t_u = world_from_lidar.poses_at(unique_times)
    R, t = R_u[at], t_u[at]  # (N, 3, 3), (N, 3)
    d_sensor = pattern.unit_directions.reshape(-1, 3)
    F = lidar.footprint_rays
    if F == 1:  # the axis alone
        rays_world = np.einsum("nij,nj->ni", R, d_sensor)[:, None, :]
    else:
        rays_sensor = footprint_directions(d_sensor, footprint_offsets(lidar.divergence_mrad * 1e-3, F))  # (N, F, 3)
        rays_world = np.einsum("nij,nfj->nfi", R, rays_sensor)  # ray 0 is the axis
    rng_, normal, oid, iid = cast(np.repeat(t, F, axis=0), rays_world.reshape(-1, 3), np.repeat(cast_times, F))
    rng_, oid, iid = rng_.reshape(-1, F), oid.reshape(-1, F), iid.reshape(-1, F)
    cos_inc = np.abs(np.einsum("nfi,nfi->nf", normal.reshape(-1, F, 3), rays_world))
    cos_inc = np.clip(cos_inc, 0.0, 1.0)
    hit = np.isfinite(rng_)
    rho = np.full(rng_.shape, float(lidar.reflectivity))
    for obj, value in (reflectivity or {}).items():
        rho[oid == obj] = value
    intensity = return_intensity(rho, cos_inc, rng_, lidar.attenuation_per_m)
    in_range = hit & (rng_ >= lidar.min_range_m) & (rng_ <= lidar.max_range_m)
    valid = (in_range & (intensity >= lidar.min_intensity)
             & (cos_inc >= np.cos(np.radians(lidar.max_incidence_deg)) - 1e-15))
    if F == 1:  # one ray: its return is first, strongest and last
        returns = np.repeat(np.where(valid, rng_, np.inf), 3, axis=1)
        return_int = np.repeat(np.where(valid, intensity, 0.0), 3, axis=1)
    else:
        returns, return_int = select_returns(rng_, intensity, valid)
    mode = RETURN_MODES.index(lidar.return_mode)
    gen = seeds.rng(*noise_key)
    noise = gen.standard_normal(len(times)) * lidar.range_noise_m
    lost = gen.random(len(times)) < lidar.dropout_rate
    selected = returns[:, mode]
    has_return = np.isfinite(selected) & ~lost
    measured = np.where(has_return, selected + noise, np.nan)
    axis_range = rng_[:, 0]
    axis_hit = hit[:, 0]
    with np.errstate(invalid="ignore"):
        point_sensor = np.where(axis_hit[:, None], axis_range[:, None] * d_sensor, np.nan)
        point_world = np.where(axis_hit[:, None], t + axis_range[:, None] * rays_world[:, 0], np.nan)
    incidence = np.where(axis_hit, np.arccos(cos_inc[:, 0]), np.nan)
    shape = lambda a: a.reshape((M, C) + a.shape[1:])  # noqa: E731
    return {
        "column": np.arange(M, dtype=np.uint32),
        "channel": np.broadcast_to(pattern.channel, (M, C)).copy(),
        "ring": np.broadcast_to(pattern.rings(), (M, C)).copy(),
        "beam_time_s": shape(times),
        "azimuth_rad": pattern.azimuth_rad, "elevation_rad": pattern.elevation_rad,
        "range_m": shape(np.where(axis_hit, axis_range, np.inf)),
        "point_sensor_m": shape(point_sensor), "point_world_m": shape(point_world),
        "object_id": shape(np.where(axis_hit, oid[:, 0], 0).astype(np.uint32)),
        "instance_id": shape(np.where(axis_hit, iid[:, 0], 0).astype(np.uint32)),
        "incidence_rad": shape(incidence),
        "sensor_position_m": shape(t), "sensor_quat_wxyz": shape(quat_wxyz_from_matrix(R_u)[at]),
        "returns_m": shape(returns),
        "intensity": shape(np.where(has_return, return_int[:, mode], 0.0).astype(np.float32)),
        "measured_range_m": shape(measured),
        "measured_point_m": shape(measured[:, None] * d_sensor),
        "dropped": shape(axis_hit & (axis_range >= lidar.min_range_m) & (axis_range <= lidar.max_range_m)
                         & ~has_return),
    }
