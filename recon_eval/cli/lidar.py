"""``recon-eval lidar-deskew`` and ``lidar-range``: a LiDAR sweep scored against a dataset's
per-beam truth (docs/metrics.md, "LiDAR"). The cloud (KITTI ``.bin`` or ``.npy``) has one point
per returned beam of the sweep, in the stream's order: the order ``scenegen export --format
kitti-velodyne`` writes."""
from __future__ import annotations

import numpy as np

from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.lidar import deskew_error, deskew_truth, range_error
from recon_eval.readers.point_rows import read_point_rows
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.tasks.lidar_truth import REFERENCES, sweep_truth


def common(p) -> None:
    p.add_argument("cloud", help="the sweep's points, one per returned beam in stream order: a KITTI .bin or .npy")
    p.add_argument("dataset", help="a scenegen dataset with a LiDAR stream")
    p.add_argument("--stream", help="the LiDAR stream (default: the dataset's only one)")
    p.add_argument("--sweep", type=int, default=0, help="the sweep (frame) index (default 0)")


def deskew_arguments(p) -> None:
    common(p)
    p.add_argument("--ref", choices=REFERENCES, default="start",
                   help="the reference time the cloud is de-skewed to: the sweep's first beam or its last")


def _load(a):
    truth = sweep_truth(read_dataset(a.dataset), a.stream, a.sweep)
    est = read_point_rows(a.cloud)
    if len(est) != len(truth.measured_m):
        raise InputError(f"{a.cloud}: {len(est)} points, but sweep {a.sweep} has {len(truth.measured_m)} returned "
                         "beams (one point per returned beam, in stream order)")
    return truth, est


def score_deskew(a):
    truth, est = _load(a)
    R, t = truth.world_from_lidar[a.ref]
    res = deskew_error(est, deskew_truth(truth.points_world, R, t), truth.raw_points)
    inputs = {"est": a.cloud, "gt": a.dataset, "gt_kind": "scenegen-dataset lidar stream", "stream": a.stream,
              "sweep": a.sweep, "reference": a.ref}
    return inputs, {"deskew": res}, no_figures


def score_range(a):
    truth, est = _load(a)
    res = range_error(np.linalg.norm(est, axis=1), truth.true_m, truth.incidence_rad)
    inputs = {"est": a.cloud, "gt": a.dataset, "gt_kind": "scenegen-dataset lidar stream", "stream": a.stream,
              "sweep": a.sweep}
    return inputs, {"range": res}, no_figures


COMMANDS = {"lidar-deskew": scored(deskew_arguments, score_deskew),
            "lidar-range": scored(common, score_range)}
