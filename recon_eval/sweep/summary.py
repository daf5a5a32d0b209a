"""Per-trial scores, per-cell statistics and breakdown points of a sweep (docs/fmatrix_survey.md).

The survey's measure (Armangue and Salvi 2003) is taken against the TRUTH: the distances
of the noise-free truth points t1, t2 of a trial's inlier rows to the epipolar lines of the
estimated F (:func:`recon_eval.metrics.epipolar.epipolar_distance_stats`: t2 to F t1 and t1 to
F^T t2, 2 n_in distances), so that it measures the estimate, not the noise. The same rows give
the Sampson RMS and the pose error through the truth K (SuperGlue's max of rotation and
translation-direction angles).

A cell (method, sigma, outlier fraction) pools its trials: ``epi_mean_px`` and ``epi_std_px`` are
the mean and standard deviation of all its trials' distances (every trial has the same number of
inliers), over the trials whose F is usable; ``median_trial_epi_px`` is the median over all
trials of each trial's mean distance (a failed trial counts as inf); ``success_rate`` the fraction
of trials with a usable F whose mean distance is at most the breakdown threshold. The breakdown
point of a method at a sigma is the smallest swept outlier fraction whose
``median_trial_epi_px`` exceeds the threshold (None: none did).

The other kinds (:mod:`recon_eval.sweep.kinds`) score one error per trial (the kind's
``error_key``: H's mean corner error, E's pose error, PnP's reprojection of the truth points,
triangulation's mean 3D error), on the trial's inlier truth; :func:`summarise_scores` gives a cell
the mean and std of those per-trial errors over the usable trials, their median over all trials
(a failure counts as inf), the medians of the secondary scores, and the success rate; the
breakdown point is defined as for F on ``median_trial_<error_key>``.
"""
from __future__ import annotations

import math

import numpy as np

from recon_eval.metrics.epipolar import epipolar_distance_stats, fundamental_metrics, pose_error_from_fundamental


def score_trial(F, trial, truth) -> dict:
    """The scores of one estimate (F (3, 3), or None for a failure) on a trial's inlier truth."""
    F = np.full((3, 3), np.nan) if F is None else np.asarray(F, np.float64)
    t1, t2 = trial.t1[trial.inliers], trial.t2[trial.inliers]
    epi = epipolar_distance_stats(F, t1, t2)
    fm = fundamental_metrics(F, t1, t2)
    pe = pose_error_from_fundamental(F, truth.K1, truth.K2, t1, t2, truth.R, truth.t)
    return {"epi_mean_px": epi.mean_px, "epi_std_px": epi.std_px, "sampson_rms_px": fm.sampson_rms_px,
            "pose_err_deg": pe.pose_err_deg, "failed": epi.failed, "failure_reason": epi.failure_reason}


def summarise_cell(trials: list[dict], breakdown_px: float) -> dict:
    """Cell statistics of its trials' scores (module docstring)."""
    ok = [t for t in trials if not t["failed"]]
    if ok:
        means = np.array([t["epi_mean_px"] for t in ok])
        second = np.array([t["epi_std_px"] ** 2 + t["epi_mean_px"] ** 2 for t in ok])
        mean = float(np.mean(means))
        std = float(math.sqrt(max(float(np.mean(second)) - mean ** 2, 0.0)))
    else:
        mean = std = math.inf
    med = lambda k: float(np.median([t[k] for t in trials]))  # noqa: E731  (failed: inf)
    return {"epi_mean_px": mean, "epi_std_px": std, "median_trial_epi_px": med("epi_mean_px"),
            "sampson_rms_px": med("sampson_rms_px"), "pose_err_deg": med("pose_err_deg"),
            "success_rate": sum(t["epi_mean_px"] <= breakdown_px for t in ok) / len(trials),
            "n_failed": len(trials) - len(ok)}


def summarise_scores(trials: list[dict], breakdown: float, key: str, extras: tuple) -> dict:
    """Cell statistics (module docstring) of trials scored by one error ``key``, and the medians of
    the secondary scores ``extras``."""
    ok = [t for t in trials if not t["failed"]]
    vals = np.array([t[key] for t in ok], np.float64)
    mean, std = (float(np.mean(vals)), float(np.std(vals))) if ok else (math.inf, math.inf)
    med = lambda k: float(np.median([t[k] for t in trials]))  # noqa: E731  (failed: inf)
    return {f"mean_{key}": mean, f"std_{key}": std, f"median_trial_{key}": med(key),
            **{f"median_{k}": med(k) for k in extras},
            "success_rate": sum(t[key] <= breakdown for t in ok) / len(trials), "n_failed": len(trials) - len(ok)}


def breakdown_points(cells: list[dict], breakdown_px: float, key: str = "median_trial_epi_px") -> list[dict]:
    """Per method and sigma: the smallest outlier fraction whose median trial error (``key``) exceeds
    ``breakdown_px`` (the threshold, in the kind's unit; None when none did), with the largest
    fraction swept."""
    out = {}
    for c in sorted(cells, key=lambda c: c["outlier_fraction"]):
        row = out.setdefault((c["method"], c["sigma_px"]), {
            "method": c["method"], "family": c["family"], "sigma_px": c["sigma_px"], "breakdown_fraction": None,
            "max_fraction_swept": c["outlier_fraction"]})
        row["max_fraction_swept"] = c["outlier_fraction"]
        if row["breakdown_fraction"] is None and not c[key] <= breakdown_px:
            row["breakdown_fraction"] = c["outlier_fraction"]
    return list(out.values())
