"""``recon-eval depth-sensor``: a depth sensor's output against its truth, from a ToF stream of a
scenegen dataset (docs/dataset_format.md, "The ToF stream"): the sensor's own decoded range (or a
user's range maps, e.g. a ToF denoiser's or multipath corrector's, ``--est``) scored with
:func:`recon_eval.metrics.depth_sensor.depth_sensor_metrics` (error by range and incidence,
completeness map, flying-pixel edges from the stream's ``flying`` truth) and with the Eigen depth
metrics on z-depth (:func:`recon_eval.metrics.depth.eigen_depth_metrics`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.depth import eigen_depth_metrics
from recon_eval.metrics.depth_sensor import depth_sensor_metrics
from recon_eval.readers.npy import read_npy
from recon_eval.readers.scenegen_dataset import is_dataset
from recon_eval.tasks.headlines import depth_headline
from scenegen.dataset import Dataset, DatasetError

#: Default bins of the true range, metres, and of the incidence angle, degrees.
RANGE_BINS_M = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 10.0)
INCIDENCE_BINS_DEG = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0)


def arguments(p) -> None:
    p.add_argument("dataset", help="a scenegen dataset holding a ToF stream")
    p.add_argument("--stream", help="the ToF stream (default: the dataset's only one)")
    p.add_argument("--est", help="range maps to score instead of the sensor's own range_m: .npy (N, H, W) or (H, W), "
                                 "metres along each pixel's ray, NaN = no measurement")
    p.add_argument("--outlier", type=float, default=0.05, help="|error| counted as an outlier, metres (default 0.05)")
    p.add_argument("--range-bins", type=float, nargs="+", default=list(RANGE_BINS_M), metavar="M",
                   help="bin edges of the true range, metres")


def _stream(path: str, name: str | None):
    if not is_dataset(path):
        raise InputError(f"{path}: not a scenegen dataset (expected a directory with manifest.json and cameras.json)")
    try:
        streams = Dataset(path).streams
        tof = streams.of_kind("tof")
        if name is None:
            if len(tof) != 1:
                raise InputError(f"{path}: {len(tof)} ToF streams ({', '.join(tof) or 'none'}); name one with --stream")
            name = tof[0]
        elif name not in tof:
            raise InputError(f"{path}: no ToF stream {name!r}; its ToF streams: {', '.join(tof) or 'none'}")
        return name, streams[name]
    except DatasetError as exc:
        raise InputError(str(exc)) from None


def score(a):
    name, s = _stream(a.dataset, a.stream)
    try:
        truth, depth_true = s.field("range_true_m"), s.field("depth_true_m").astype(np.float64)
        incidence, flying = s.field("incidence_deg"), s.field("flying")
        own = a.est is None
        est = s.field("range_m").astype(np.float64) if own else read_npy(a.est, None)
    except DatasetError as exc:
        raise InputError(str(exc)) from None
    if est.ndim == 2:
        est = est[None]
    if est.shape != truth.shape:
        raise InputError(f"{a.est}: expected range maps of shape {truth.shape} (the stream's frames), got {est.shape}")
    with np.errstate(invalid="ignore", divide="ignore"):
        ray_z = np.where(np.isfinite(truth) & (truth > 0), depth_true / truth, np.nan)  # per pixel, from the truth
    depth_est = est * ray_z
    res = {"sensor": depth_sensor_metrics(est, truth, range_bins_m=np.asarray(a.range_bins), incidence_deg=incidence,
                                          incidence_bins_deg=np.asarray(INCIDENCE_BINS_DEG), edge_mask=flying,
                                          outlier_m=a.outlier),
           "eigen": eigen_depth_metrics(list(depth_est), list(depth_true), alignment="none")}
    inputs = {"dataset": str(Path(a.dataset)), "stream": name, "est": a.est or f"{name}: range_m (the sensor's own)",
              "gt_kind": "scenegen-dataset ToF stream range_true_m / depth_true_m", "outlier_m": a.outlier}
    return inputs, res, no_figures


COMMANDS = {"depth-sensor": scored(arguments, score, lambda a, res: depth_headline(res["eigen"], "none")
                                   | {"completeness": res["sensor"].completeness,
                                      "edge_outlier_rate": res["sensor"].edge_outlier_rate})}
