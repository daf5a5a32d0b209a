"""What a LiDAR sweep asks of a scene: rays posed by the LiDAR at their own times (:class:`PosedRays`),
and what it gets back per ray (:class:`RayHits`); a :data:`BeamCast` answers one with the other.

Two answer the same, bit for bit: :func:`beam_cast_by_rays` in numpy around any ray cast (the
definition: the tests' closed-form scenes, Mitsuba through ``Caster.cast_at_times``), and the
renderer's one kernel (``Caster.cast_beams``: the poses gathered, the rays rotated, cast, and the
hits' points and incidence computed where the rays are, with no array per ray in numpy but the
answers). Dot products are summed in one stated order (:func:`scenegen.geometry.lidar.dot3`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from scenegen.geometry.lidar import dot3, rotate3


@dataclass(frozen=True, eq=False)
class PosedRays:
    """R rays of a sweep: ``times_s`` (U,) the distinct cast times (s, increasing),
    ``world_from_lidar`` ((U, 3, 3) R, (U, 3) t) and ``quat_wxyz`` (U, 4) the LiDAR's pose at
    them, ``time_index`` (R,) each ray's index into them, ``directions_lidar`` (R, 3) each ray's
    unit direction in the LiDAR frame (from the LiDAR's origin)."""

    times_s: np.ndarray
    world_from_lidar: tuple[np.ndarray, np.ndarray]
    quat_wxyz: np.ndarray
    time_index: np.ndarray
    directions_lidar: np.ndarray


@dataclass(frozen=True, eq=False)
class RayHits:
    """Per ray of a :class:`PosedRays` (world frame unless named): ``range_m`` (R,) to the first
    surface (inf: none), ``cos_incidence`` (R,) ``|n . d|`` clipped to [0, 1] (0: none),
    ``object_id`` / ``instance_id`` (R,) uint32 (0: none), ``point_world_m`` and
    ``point_lidar_m`` (R, 3) the hit (NaN: none), ``sensor_position_m`` (R, 3) and
    ``sensor_quat_wxyz`` (R, 4) the LiDAR's pose at the ray's time."""

    range_m: np.ndarray
    cos_incidence: np.ndarray
    object_id: np.ndarray
    instance_id: np.ndarray
    point_world_m: np.ndarray
    point_lidar_m: np.ndarray
    sensor_position_m: np.ndarray
    sensor_quat_wxyz: np.ndarray


BeamCast = Callable[[PosedRays], RayHits]
#: cast(origins (R, 3), directions (R, 3) unit, times (R,) s) -> ((R,) range m, inf = none,
#: (R, 3) unit surface normals, (R,) uint32 object ids, (R,) uint32 instance ids), world frame.
RayCast = Callable[[np.ndarray, np.ndarray, np.ndarray], tuple]


def world_directions(rays: PosedRays) -> np.ndarray:
    """(R, 3) the rays' world directions: the LiDAR's rotation at each ray's time times its
    LiDAR-frame direction (:func:`rotate3`)."""
    R = rays.world_from_lidar[0][rays.time_index]
    d = rays.directions_lidar
    rows = [[R[:, i, j] for j in range(3)] for i in range(3)]
    return np.stack(rotate3(rows, [d[:, j] for j in range(3)]), axis=1)


def beam_cast_by_rays(cast: RayCast) -> BeamCast:
    """The :data:`BeamCast` of a ray cast, in numpy (module docstring)."""

    def cast_beams(rays: PosedRays) -> RayHits:
        at = rays.time_index
        origin = rays.world_from_lidar[1][at]
        direction = world_directions(rays)
        rng, normal, oid, iid = cast(origin, direction, rays.times_s[at])
        hit = np.isfinite(rng)
        cos = np.abs(dot3([normal[:, i] for i in range(3)], [direction[:, i] for i in range(3)]))
        with np.errstate(invalid="ignore"):
            point_world = np.where(hit[:, None], origin + rng[:, None] * direction, np.nan)
            point_lidar = np.where(hit[:, None], rng[:, None] * rays.directions_lidar, np.nan)
        return RayHits(range_m=np.where(hit, rng, np.inf), cos_incidence=np.where(hit, np.clip(cos, 0.0, 1.0), 0.0),
                       object_id=np.where(hit, oid, 0).astype(np.uint32),
                       instance_id=np.where(hit, iid, 0).astype(np.uint32),
                       point_world_m=point_world, point_lidar_m=point_lidar, sensor_position_m=origin,
                       sensor_quat_wxyz=rays.quat_wxyz[at])

    return cast_beams
