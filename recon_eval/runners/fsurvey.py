"""The survey's nineteen fundamental-matrix estimators (:mod:`recon_eval.estimators.fundamental`)
on the cross-view putative match sets, scored exactly as OpenCV's F runners
(:func:`recon_eval.runners.twoview.fundamental`: the same files, metrics and notes).

What each is fed, as the OpenCV runners are: the robust family every match of the set (outliers
included); the linear and iterative families, which have no outlier stage, the labelled inliers
only (as ``opencv-f-8point``); the 7-point method seven labelled inliers drawn with
:data:`recon_eval.runners.twoview.SEVEN_POINT_SEED`, of whose up to three solutions the one with
the lowest median Sampson error on the labelled inliers is kept (as ``opencv-f-7point``). The
robust methods are seeded with ``options["seed"]`` (default 0).
"""
from __future__ import annotations

import numpy as np

from recon_eval.estimators.fundamental import estimate, estimator, linear
from recon_eval.runners import twoview
from recon_eval.runners.common import RunOutput


def fundamental(ds, out_dir, options) -> RunOutput:
    """Estimator ``options["estimator"]`` on every match set of every cross-view pair."""
    name, seed = options["estimator"], int(options.get("seed", 0))
    e = estimator(name)
    flag = "7point" if name == "seven-point" else ("8point" if e.family != "robust" else "survey")

    def fit(i, j, kind, x1, x2):
        if name == "seven-point":
            sols = linear.seven_point_solutions(x1, x2)
            return (np.concatenate(sols) if sols else None), None
        est = estimate(name, x1, x2, seed=seed)
        if not np.all(np.isfinite(est.F)):
            return None, None
        return est.F, est.inliers

    out = twoview.fundamental(ds, out_dir, {"flag": flag}, fit=fit)
    out.notes["estimator"] = {"name": name, "family": e.family, "survey_label": e.label, "cites": e.cites,
                              "params": dict(e.params), "seed": seed if e.seeded else None,
                              "fed": "every match" if e.family == "robust" else "the labelled inliers"}
    return out
