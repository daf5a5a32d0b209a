"""A LiDAR sweep's truth read from a dataset stream for scoring (recon_eval.metrics.lidar): the
returned beams in stream order (those with a measured range: the points the exports write, in
their order), their true hits, raw measured points and ranges, incidence angles, and the
LiDAR's pose at the sweep's start and end (its first and last beams' recorded poses)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from scenegen.geometry.rotation import matrix_from_quat_wxyz

REFERENCES = ("start", "end")


@dataclass(frozen=True, eq=False)
class SweepTruth:
    """One sweep's returned beams (N of them, stream order) and the reference poses."""

    points_world: np.ndarray  # (N, 3) true hits, world, m (NaN where the axis met nothing)
    raw_points: np.ndarray  # (N, 3) measured points, LiDAR frame at each beam's time, m
    measured_m: np.ndarray  # (N,) measured ranges
    true_m: np.ndarray  # (N,) true ranges of the beams' axes
    incidence_rad: np.ndarray  # (N,)
    world_from_lidar: dict  # reference name -> ((3, 3) R, (3,) t)


def sweep_truth(ds, stream: str | None, sweep: int) -> SweepTruth:
    """The truth of sweep ``sweep`` of LiDAR stream ``stream`` (default: the only one) of ``ds``
    (a :class:`recon_eval.readers.scenegen_dataset.DatasetTruth`)."""
    names = ds.read(lambda: ds.dataset.streams.of_kind("lidar"))
    if not names:
        raise NotApplicable(f"{ds.dataset.root}: no LiDAR stream")
    if stream is None:
        if len(names) != 1:
            raise InputError(f"the dataset has {len(names)} LiDAR streams ({', '.join(names)}): pass --stream")
        stream = names[0]
    if stream not in names:
        raise InputError(f"unknown LiDAR stream {stream!r}; the dataset's: {', '.join(names)}")
    s = ds.read(lambda: ds.dataset.streams[stream])
    field = lambda k: ds.read(s.field, k)  # noqa: E731
    rows = field("sweep") == sweep
    if not rows.any():
        raise InputError(f"stream {stream!r} has no sweep {sweep} (sweeps 0 .. {int(field('sweep').max())})")
    measured = field("measured_range_m")[rows].reshape(-1)
    keep = np.isfinite(measured)
    per_beam = lambda k, n: field(k)[rows].reshape((-1,) + n)  # noqa: E731
    pos, quat = per_beam("sensor_position_m", (3,)), per_beam("sensor_quat_wxyz", (4,))
    times = per_beam("beam_time_s", ())
    first, last = int(np.argmin(times)), int(np.argmax(times))
    poses = {"start": (matrix_from_quat_wxyz(quat[first]), pos[first]),
             "end": (matrix_from_quat_wxyz(quat[last]), pos[last])}
    return SweepTruth(per_beam("point_world_m", (3,))[keep], per_beam("measured_point_m", (3,))[keep],
                      measured[keep], per_beam("range_m", ())[keep], per_beam("incidence_rad", ())[keep], poses)
