"""Summary statistics (evo's set), recall-curve areas and the Image Matching Benchmark's mAA, shared by
several metric families."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError


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


#: The Image Matching Benchmark's pose-accuracy histogram: bins [0, 1), [1, 2), ..., [9, 10] degrees.
IMB_BINS_DEG = np.arange(11)


def maa_deg(pose_err_deg, max_threshold_deg: int = 10) -> float:
    """Image Matching Benchmark mean average accuracy (ubc-vision/image-matching-benchmark,
    utils/pack_helper.py ``compute_qt_auc``): ``np.histogram`` of the pose errors (max(err_q, err_t),
    degrees) over its 10 bins ``np.arange(11)``, divided by the pair count and cumulated; mAA@m is
    the mean of the first ``m`` cumulated values (IMB's ``qt_auc_05`` = ``np.mean(qt_acc[:5])``,
    ``qt_auc_10`` = ``np.mean(qt_acc)``). numpy closes only the last bin, so at thresholds 1 .. 9 a
    pair counts when ``err < th`` and at 10 when ``err <= 10``: an error of exactly 5 deg does not
    count in mAA@5. ``max_threshold_deg``: 1 .. 10. Failures (inf, NaN) are misses (IMB maps inf to
    1e6). Discrete: not the same number as the AUC. Empty -> 0."""
    m = int(max_threshold_deg)
    if m != max_threshold_deg or not 1 <= m <= 10:
        raise InputError(f"mAA: max_threshold_deg: expected an integer 1 .. 10 (the Image Matching Benchmark's "
                         f"histogram has 10 one-degree bins), got {max_threshold_deg!r}")
    e = np.asarray(pose_err_deg, float).reshape(-1)
    if len(e) == 0:
        return 0.0
    e = np.where(np.isfinite(e), e, 1e6)
    hist, _ = np.histogram(e, IMB_BINS_DEG)
    return float(np.mean(np.cumsum(hist.astype(float) / float(len(e)))[:m]))
