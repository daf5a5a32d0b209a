"""LiDAR scan patterns and the return model, in numpy (docs/scene_spec.md, "LiDARs").

The LiDAR frame: +x forward, +y left, +z up (a Velodyne's and KITTI's velodyne frame). A beam's
``azimuth`` is measured from +x towards +y (counter-clockwise seen from above), its
``elevation`` up from the xy plane; its unit direction is
``(cos el cos az, cos el sin az, sin el)`` (:func:`beam_directions`).

A pattern (:class:`ScanPattern`) is a sweep of ``M`` samples of ``C`` beams: a spinning head's
columns (all channels once per column) or a solid-state raster's lines. Sample ``j`` is stamped
``sample_time_s[j]`` after the sweep starts; beam ``(j, c)`` fires ``beam_time_s[j, c]`` after the
sweep starts (its own time: the head keeps turning between firings) in the direction
``(azimuth_rad[j, c], elevation_rad[j, c])``.

* Spinning (:func:`spinning_pattern`): ``columns`` columns per turn at ``rate_hz`` turns a second;
  column ``j`` starts at ``j / (columns rate_hz)``, channel ``c`` fires ``firing_offset_s[c]``
  later, at azimuth ``start + s 2 pi rate_hz t + azimuth_offset[c]`` (``s = -1`` when the head
  turns clockwise seen from above, as Velodyne and Ouster heads do).
* Raster (:func:`raster_pattern`, a MEMS-mirror solid-state model): ``rows`` lines top to bottom,
  each of ``columns`` points left to right over ``fov_h`` x ``fov_v``, evenly in time over the
  sweep ``1 / rate_hz``.

The return model (:func:`return_intensity`, :func:`select_returns`): a footprint ray hitting a
surface of reflectivity ``rho`` at incidence ``theta`` and range ``r`` returns the intensity
``rho cos(theta) exp(-2 alpha r)`` (a Lambertian target, range-normalised as calibrated
reflectivity is, with two-way atmospheric attenuation ``alpha``: CARLA's ``exp(-a d)`` model,
stated per metre of the two-way path); a ray whose intensity is below ``min_intensity`` or
whose incidence exceeds ``max_incidence`` gives no return. A beam's footprint (full divergence
angle) is sampled by a centre ray and a ring of rays at half the divergence; its first, strongest
and last returns are the nearest, brightest and farthest of its rays' returns.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

#: Names of a beam's returns, in the order of the ``returns_m`` columns.
RETURN_MODES = ("first", "strongest", "last")


@dataclass(frozen=True, eq=False)
class ScanPattern:
    """One sweep (module docstring): ``sample_time_s`` (M,) and ``beam_time_s`` (M, C) seconds
    from the sweep's start, ``azimuth_rad`` / ``elevation_rad`` (M, C) in the LiDAR frame,
    ``channel`` (C,) the laser index of each beam column; ``duration_s`` the sweep's length."""

    sample_time_s: np.ndarray
    beam_time_s: np.ndarray
    azimuth_rad: np.ndarray
    elevation_rad: np.ndarray
    channel: np.ndarray
    duration_s: float

    @property
    def shape(self) -> tuple[int, int]:
        """(M samples, C beams per sample)."""
        return self.beam_time_s.shape

    @cached_property
    def unit_directions(self) -> np.ndarray:
        """(M, C, 3) unit beam directions in the LiDAR frame, computed once (read-only)."""
        d = beam_directions(self.azimuth_rad, self.elevation_rad)
        d.flags.writeable = False
        return d

    def directions(self) -> np.ndarray:
        """(M, C, 3) unit beam directions in the LiDAR frame."""
        return self.unit_directions.copy()

    @cached_property
    def distinct_beam_times(self) -> tuple[np.ndarray, np.ndarray]:
        """((U,) the distinct ``beam_time_s`` values, increasing; (M C,) each beam's index into
        them), computed once (read-only): a spinning head whose channels fire together has one
        time per column."""
        offsets, index = np.unique(self.beam_time_s.reshape(-1), return_inverse=True)
        offsets.flags.writeable = index.flags.writeable = False
        return offsets, index

    def beam_times_at(self, t0_s: float) -> tuple[np.ndarray, np.ndarray]:
        """``np.unique(t0_s + beam_time_s, return_inverse=True)`` (the distinct firing times of the
        sweep that starts at ``t0_s`` s, and each beam's index into them), bit for bit, from
        :attr:`distinct_beam_times`: adding ``t0_s`` keeps the order, and may only merge
        neighbours that round to the same time."""
        offsets, index = self.distinct_beam_times
        times, merged = np.unique(t0_s + offsets, return_inverse=True)
        return times, merged[index]

    def rings(self, elevations_rad=None) -> np.ndarray:
        """(C,) each beam column's ring: its rank by nominal elevation, 0 = lowest (the ``ring``
        of the Velodyne ROS driver and nuScenes' point clouds)."""
        el = self.elevation_rad[0] if elevations_rad is None else np.asarray(elevations_rad)
        ring = np.empty(len(el), np.uint16)
        ring[np.argsort(el, kind="stable")] = np.arange(len(el), dtype=np.uint16)
        return ring


def beam_directions(azimuth_rad, elevation_rad) -> np.ndarray:
    """(..., 3) unit directions of beams at ``azimuth_rad`` / ``elevation_rad`` (same shapes)."""
    az, el = np.asarray(azimuth_rad, np.float64), np.asarray(elevation_rad, np.float64)
    ce = np.cos(el)
    return np.stack([ce * np.cos(az), ce * np.sin(az), np.sin(el)], axis=-1)


def spinning_pattern(*, elevations_deg, azimuth_offsets_deg, firing_offsets_s, columns: int, rate_hz: float,
                     clockwise: bool = True, start_azimuth_deg: float = 0.0) -> ScanPattern:
    """A spinning head's sweep (module docstring). ``elevations_deg`` (C,), ``azimuth_offsets_deg``
    (C,) (counter-clockwise, degrees), ``firing_offsets_s`` (C,) each channel's delay after its
    column's start, each below the column period ``1 / (columns rate_hz)``."""
    el = np.radians(np.asarray(elevations_deg, np.float64))
    az_off = np.radians(np.asarray(azimuth_offsets_deg, np.float64))
    fire = np.asarray(firing_offsets_s, np.float64)
    period = 1.0 / (columns * rate_hz)
    if not (len(el) == len(az_off) == len(fire)):
        raise ValueError(f"a spinning pattern needs one azimuth offset and one firing offset per channel "
                         f"({len(el)} elevations, {len(az_off)} azimuth offsets, {len(fire)} firing offsets)")
    if len(fire) and (fire.min() < 0 or fire.max() >= period):
        raise ValueError(f"firing offsets must lie in [0, {period:.6g}) s (one column at {columns} columns "
                         f"and {rate_hz:g} Hz), got [{fire.min():.6g}, {fire.max():.6g}] s")
    t_col = np.arange(columns, dtype=np.float64) * period  # (M,)
    t_beam = t_col[:, None] + fire[None, :]  # (M, C)
    sign = -1.0 if clockwise else 1.0
    az = np.radians(start_azimuth_deg) + sign * 2.0 * np.pi * rate_hz * t_beam + az_off[None, :]
    az = np.mod(az + np.pi, 2.0 * np.pi) - np.pi  # (-pi, pi]
    elev = np.broadcast_to(el, t_beam.shape).copy()
    return ScanPattern(t_col, t_beam, az, elev, np.arange(len(el), dtype=np.uint16), 1.0 / rate_hz)


def raster_pattern(*, fov_h_deg: float, fov_v_deg: float, rows: int, columns: int, rate_hz: float) -> ScanPattern:
    """A solid-state raster sweep (module docstring): sample ``j`` is line ``j`` (top first),
    its beams the line's ``columns`` points left (+y) to right, evenly spaced in angle and time."""
    n = rows * columns
    step = 1.0 / (n * rate_hz)
    t_line = np.arange(rows, dtype=np.float64) * columns * step
    t_beam = t_line[:, None] + np.arange(columns, dtype=np.float64)[None, :] * step
    half_h, half_v = np.radians(fov_h_deg) / 2.0, np.radians(fov_v_deg) / 2.0
    az_line = np.linspace(half_h, -half_h, columns) if columns > 1 else np.zeros(1)
    el_rows = np.linspace(half_v, -half_v, rows) if rows > 1 else np.zeros(1)
    az = np.broadcast_to(az_line[None, :], t_beam.shape).copy()
    el = np.broadcast_to(el_rows[:, None], t_beam.shape).copy()
    return ScanPattern(t_line, t_beam, az, el, np.arange(columns, dtype=np.uint16), 1.0 / rate_hz)


def footprint_offsets(divergence_rad: float, rays: int) -> np.ndarray:
    """(R, 2) angular offsets (a, b) in radians of a beam's footprint rays about its axis: the
    centre (0, 0) first, then ``rays - 1`` evenly around a circle of radius ``divergence / 2``."""
    if rays < 1:
        raise ValueError(f"a beam needs at least 1 ray, got {rays}")
    ring = np.arange(rays - 1, dtype=np.float64) * 2.0 * np.pi / max(rays - 1, 1)
    r = divergence_rad / 2.0
    return np.concatenate([np.zeros((1, 2)), np.stack([r * np.cos(ring), r * np.sin(ring)], 1)])


def footprint_directions(directions, offsets) -> np.ndarray:
    """(N, R, 3) unit ray directions of beams (N, 3) with footprint ``offsets`` (R, 2): ray
    ``(a, b)`` makes the angle ``sqrt(a^2 + b^2)`` with its beam's axis, towards ``a`` along the
    beam's horizontal tangent (+azimuth) and ``b`` along its tangent towards +z (offset (0, 0) is
    the axis itself, bit for bit)."""
    d = np.asarray(directions, np.float64)
    up = np.array([0.0, 0.0, 1.0])
    h = np.cross(up, d)  # horizontal tangent
    hn = np.linalg.norm(h, axis=1, keepdims=True)
    h = np.where(hn > 1e-12, h / np.where(hn > 1e-12, hn, 1.0), np.array([0.0, 1.0, 0.0]))
    v = np.cross(d, h)
    a, b = offsets[:, 0], offsets[:, 1]
    ang = np.hypot(a, b)
    safe = np.where(ang > 0, ang, 1.0)
    ca, sa = np.cos(ang)[None, :, None], np.sin(ang)[None, :, None]
    tangent = (a / safe)[None, :, None] * h[:, None, :] + (b / safe)[None, :, None] * v[:, None, :]
    rays = ca * d[:, None, :] + sa * tangent
    rays[:, ang == 0] = d[:, None, :]
    return rays


def dot3(x, y, zero=0.0):
    """``x . y`` of 3-vectors given as components ``x[0], x[1], x[2]`` (numpy or Dr.Jit arrays
    alike), summed as ``((x0 y0 + x2 y2) + x1 y1) + 0``: the order numpy's ``einsum`` sums a
    3-term contraction in (numpy 2.4, x86-64; its accumulator starts at +0, so a -0 sum is +0),
    written out so that a beam's rays and incidence have the same bits in numpy and in a
    renderer's kernel. ``zero``: the 0 to add (a Dr.Jit kernel needs an opaque one: it drops a
    literal ``+ 0.0``)."""
    return ((x[0] * y[0] + x[2] * y[2]) + x[1] * y[1]) + zero


def rotate3(R, v, zero=0.0) -> tuple:
    """The components of ``R v``: ``R[i][j]`` and ``v[j]`` component arrays, each row by :func:`dot3`."""
    return tuple(dot3(R[i], v, zero) for i in range(3))


def return_intensity(reflectivity, cos_incidence, range_m, attenuation_per_m: float) -> np.ndarray:
    """Intensity of returns (module docstring): ``rho cos(theta) exp(-2 alpha r)``; 0 where
    ``range_m`` is not finite (no surface)."""
    r = np.asarray(range_m, np.float64)
    hit = np.isfinite(r)
    out = np.zeros(r.shape)
    out[hit] = (np.asarray(reflectivity, np.float64)[hit] * np.asarray(cos_incidence, np.float64)[hit]
                * np.exp(-2.0 * attenuation_per_m * r[hit]))
    return out


def select_returns(range_m, intensity, valid) -> tuple[np.ndarray, np.ndarray]:
    """((N, 3) ranges, (N, 3) intensities) of the first, strongest and last returns of beams
    whose footprint rays have ``range_m`` (N, R), ``intensity`` (N, R) and ``valid`` (N, R)
    (a return); inf range and 0 intensity where a beam has no return. Ties: the lower ray index."""
    r = np.where(valid, range_m, np.inf)
    rows = np.arange(len(r))
    first = np.argmin(r, axis=1)
    last = np.argmax(np.where(valid, range_m, -np.inf), axis=1)
    strong = np.argmax(np.where(valid, intensity, -np.inf), axis=1)
    idx = np.stack([first, strong, last], 1)
    any_ = valid.any(axis=1)[:, None]
    ranges = np.where(any_, r[rows[:, None], idx], np.inf)
    inten = np.where(any_, np.asarray(intensity)[rows[:, None], idx], 0.0)
    return ranges, inten
