"""Summary statistics (evo's set) and recall-curve areas shared by several metric families."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ErrorStats:
    """evo's statistics of an error array, over the finite entries only; ``n`` counts them and
    ``n_failed`` the non-finite entries (failures, e.g. unregistered cameras = inf), which are
    reported here rather than dropped silently. Units are those of the field that holds this."""

    rmse: float
    mean: float
    median: float
    std: float  # population std (ddof = 0), as numpy/evo
    min: float
    max: float
    n: int
    n_failed: int


def error_stats(errors) -> ErrorStats:
    e = np.asarray(errors, dtype=np.float64).reshape(-1)
    ok = np.isfinite(e)
    f = e[ok]
    if len(f) == 0:
        nan = float("nan")
        return ErrorStats(nan, nan, nan, nan, nan, nan, 0, int((~ok).sum()))
    return ErrorStats(
        float(np.sqrt(np.mean(f**2))), float(np.mean(f)), float(np.median(f)), float(np.std(f)),
        float(np.min(f)), float(np.max(f)), int(len(f)), int((~ok).sum()),
    )


def recall_auc(errors, thresholds) -> tuple[float, ...]:
    """Normalised area under the recall-vs-error curve up to each threshold (SuperGlue
    ``pose_auc``, magicleap/SuperGluePretrainedNetwork models/utils.py; LoFTR ``error_auc``).

    Errors sorted; the curve passes through (0, 0) and (e_(k), k/N) and is integrated by the
    trapezoid rule up to the threshold, where it is held at the recall of the last error below it;
    the area is divided by the threshold. Failures (inf/NaN) never enter the curve but count in N.
    Empty input -> 0.
    """
    e = np.asarray(errors, dtype=np.float64).reshape(-1)
    n = len(e)
    if n == 0:
        return tuple(0.0 for _ in thresholds)
    e = np.where(np.isnan(e), np.inf, e)
    e = np.sort(e)
    recall = np.arange(1, n + 1) / n
    e = np.r_[0.0, e]
    recall = np.r_[0.0, recall]
    out = []
    for t in thresholds:
        last = int(np.searchsorted(e, t))  # errors strictly below t (side='left') enter the curve
        r = np.r_[recall[:last], recall[last - 1]]
        x = np.r_[e[:last], t]
        out.append(float(np.trapezoid(r, x=x) / t))
    return tuple(out)
