"""What a sweep kind declares (:class:`SweepKind`; the registry is :mod:`recon_eval.sweep.kinds`):
the truth it draws from a dataset, how a trial is drawn (seeded noise and outliers), the methods
it runs, and the error a cell reports, in one unit, with the breakdown threshold in that unit."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class SweepKind:
    name: str  # --kind
    label: str  # what is estimated, for tables and the report
    stream: str  # the seed stream of the trials (``<stream>-method``: the methods' seeds)
    measure: str  # one line: the per-trial error a cell pools
    error_key: str  # the per-trial score that is that error
    unit: str  # its unit (px, deg, m)
    cell_keys: tuple  # (mean, std, median-trial) keys of a cell's pooled error
    min_inliers: int  # the fewest inliers a trial may keep (the minimal solvers' size)
    default_breakdown: float  # the median-trial error (unit) above which a method has broken down
    n_views: int  # views the truth takes (--views)
    truth: Callable  # (DatasetTruth, views tuple, pool, object name or None) -> the kind's truth
    draw: Callable  # (truth, n, sigma_px, outlier_fraction, seed, cell, trial) -> a trial
    fit: Callable  # (SweepMethod, trial, truth, method seed, workdir) -> estimate or None
    score: Callable  # (estimate or None, trial, truth) -> dict of scores (error_key, failed, ...)
    summarise: Callable  # (list of trial scores, breakdown) -> cell statistics
    resolve: Callable  # (names, declared methods, notes) -> [SweepMethod]
    default_methods: Callable  # () -> names swept when --methods is not given
    notes: Callable  # (truth) -> dict for the result's inputs
