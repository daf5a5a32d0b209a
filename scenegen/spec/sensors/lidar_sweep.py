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
from scenegen.spec.sensors.lidar_beams import BeamCast, PosedRays


def sweep_fields(cast: BeamCast, lidar, pattern: ScanPattern, world_from_lidar, t0_s: float, *, reflectivity=None,
                 noise_key=(0,), static_time_s: float | None = None) -> dict[str, np.ndarray]:
    """The stream fields (``scenegen.spec.sensors.lidar.FIELDS``, less ``sweep``) of the sweep
    that starts at ``t0_s`` (s); ``cast`` a :data:`scenegen.spec.sensors.lidar_beams.BeamCast`
    (``Caster.cast_beams``, or ``beam_cast_by_rays`` of a ray cast); ``world_from_lidar`` a
    :class:`scenegen.geometry.clock.Trajectory`; ``reflectivity`` {object id: value} over
    ``lidar.reflectivity``. ``static_time_s``: cast every beam with the LiDAR and the objects at
    that one time (a "static picture" sweep, as CARLA's: for comparisons only; the beams keep
    their own times in ``beam_time_s``)."""
    M, C = pattern.shape
    times = (t0_s + pattern.beam_time_s).reshape(-1)  # (N,)
    # beams that fire together share a pose: evaluated once per distinct time (exact, and a
    # spinning head's 64 channels of a column are one time)
    if static_time_s is None:
        unique_times, at = pattern.beam_times_at(t0_s)
    else:
        unique_times, at = np.full(1, static_time_s, np.float64), np.zeros(len(times), np.intp)
    R_u, t_u = world_from_lidar.poses_at(unique_times)
    d_sensor = pattern.unit_directions.reshape(-1, 3)
    F = lidar.footprint_rays
    if F == 1:  # the axis alone
        rays = PosedRays(unique_times, (R_u, t_u), quat_wxyz_from_matrix(R_u), at, d_sensor)
    else:
        rays_sensor = footprint_directions(d_sensor, footprint_offsets(lidar.divergence_mrad * 1e-3, F))  # (N, F, 3)
        rays = PosedRays(unique_times, (R_u, t_u), quat_wxyz_from_matrix(R_u), np.repeat(at, F),
                         rays_sensor.reshape(-1, 3))  # ray 0 of each beam is its axis
    hits = cast(rays)
    rng_, cos_inc = hits.range_m.reshape(-1, F), hits.cos_incidence.reshape(-1, F)
    oid = hits.object_id.reshape(-1, F)
    hit = np.isfinite(rng_)
    intensity = return_intensity(reflectivity_of(oid, lidar.reflectivity, reflectivity), cos_inc, rng_,
                                 lidar.attenuation_per_m)
    in_range = hit & (rng_ >= lidar.min_range_m) & (rng_ <= lidar.max_range_m)
    valid = (in_range & (intensity >= lidar.min_intensity)
             & (cos_inc >= np.cos(np.radians(lidar.max_incidence_deg)) - 1e-15))
    mode = RETURN_MODES.index(lidar.return_mode)
    if F == 1:  # one ray: its return is first, strongest and last
        selected = np.where(valid[:, 0], rng_[:, 0], np.inf)
        returns = np.repeat(selected[:, None], 3, axis=1)
        selected_int = np.where(valid[:, 0], intensity[:, 0], 0.0)
    else:
        returns, return_int = select_returns(rng_, intensity, valid)
        selected, selected_int = returns[:, mode], return_int[:, mode]
    gen = seeds.rng(*noise_key)
    noise = gen.standard_normal(len(times)) * lidar.range_noise_m
    lost = gen.random(len(times)) < lidar.dropout_rate
    has_return = np.isfinite(selected) & ~lost
    measured = np.where(has_return, selected + noise, np.nan)
    axis = lambda a: a.reshape((len(times), F) + a.shape[1:])[:, 0]  # noqa: E731  (N, ...) of the axis rays
    axis_hit = hit[:, 0]
    incidence = np.where(axis_hit, np.arccos(cos_inc[:, 0]), np.nan)
    shape = lambda a: a.reshape((M, C) + a.shape[1:])  # noqa: E731
    return {
        "column": np.arange(M, dtype=np.uint32),
        "channel": np.broadcast_to(pattern.channel, (M, C)).copy(),
        "ring": np.broadcast_to(pattern.rings(), (M, C)).copy(),
        "beam_time_s": shape(times),
        "azimuth_rad": pattern.azimuth_rad, "elevation_rad": pattern.elevation_rad,
        "range_m": shape(rng_[:, 0]),
        "point_sensor_m": shape(axis(hits.point_lidar_m)), "point_world_m": shape(axis(hits.point_world_m)),
        "object_id": shape(oid[:, 0]),
        "instance_id": shape(axis(hits.instance_id)),
        "incidence_rad": shape(incidence),
        "sensor_position_m": shape(axis(hits.sensor_position_m)),
        "sensor_quat_wxyz": shape(axis(hits.sensor_quat_wxyz)),
        "returns_m": shape(returns),
        "intensity": shape(np.where(has_return, selected_int, 0.0).astype(np.float32)),
        "measured_range_m": shape(measured),
        "measured_point_m": shape(measured[:, None] * d_sensor),
        "dropped": shape(in_range[:, 0] & ~has_return),
    }


def reflectivity_of(object_id, default: float, reflectivity=None) -> np.ndarray:
    """(shape of ``object_id``) float64 reflectivity of each hit: ``reflectivity`` {object id:
    value}, ``default`` for the other ids (one table lookup)."""
    keys = [int(k) for k in (reflectivity or {})]
    table = np.full(max(keys, default=0) + 2, float(default))  # the last entry stands for every larger id
    for obj, value in (reflectivity or {}).items():
        table[int(obj)] = value
    return np.take(table, object_id, mode="clip")
