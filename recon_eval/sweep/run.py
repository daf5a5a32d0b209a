"""A sweep over noise and outliers (docs/fmatrix_survey.md, docs/sweeps.md): for every sigma x
outlier fraction x trial one trial drawn by the configuration's kind
(:data:`recon_eval.sweep.kinds.KINDS`: F, H, E, PnP, triangulation), every method on it, its scores
and the cells' statistics (:mod:`.summary`). Same truth, configuration and methods: the same numbers, bitwise (every
stream is seeded from the configuration's seed and the cell's indices; nothing timed is kept).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

from recon_eval.errors import InputError
from recon_eval.sweep.kinds import KINDS
from recon_eval.sweep.summary import breakdown_points
from scenegen.geometry.seeds import seed32


@dataclass(frozen=True)
class SweepConfig:
    sigmas_px: tuple  # Gaussian noise, px, on every coordinate
    outlier_fractions: tuple  # in [0, 1)
    trials: int  # per cell
    points: int  # correspondences per trial
    seed: int
    breakdown: float  # the median trial error (the kind's unit) above which a method has broken down
    kind: str = "f"  # a key of recon_eval.sweep.kinds.KINDS

    def check(self) -> "SweepConfig":
        if self.kind not in KINDS:
            raise InputError(f"--kind: expected one of {', '.join(KINDS)}, got {self.kind!r}")
        kind = KINDS[self.kind]
        if not self.sigmas_px or any(not (math.isfinite(s) and s >= 0) for s in self.sigmas_px):
            raise InputError(f"--sigmas: expected finite values >= 0 px, got {list(self.sigmas_px)}")
        if not self.outlier_fractions or any(not 0 <= f < 1 for f in self.outlier_fractions):
            raise InputError(f"--outliers: expected fractions in [0, 1), got {list(self.outlier_fractions)}")
        repeated = len(set(self.sigmas_px)) < len(self.sigmas_px)
        if repeated or len(set(self.outlier_fractions)) < len(self.outlier_fractions):
            raise InputError("--sigmas / --outliers: a value is given twice")
        if self.trials < 1:
            raise InputError(f"--trials: expected >= 1, got {self.trials}")
        worst = max(self.outlier_fractions)
        if self.points - round(worst * self.points) < kind.min_inliers:
            raise InputError(f"--points {self.points} at outlier fraction {worst} keeps fewer than {kind.min_inliers} "
                             f"inliers (--kind {kind.name})")
        if not (math.isfinite(self.breakdown) and self.breakdown > 0):
            raise InputError(f"--breakdown: expected a number > 0 ({kind.unit}), got {self.breakdown}")
        if not 0 <= self.seed < 2 ** 32:
            raise InputError(f"--seed: expected 0 .. 2**32 - 1, got {self.seed}")
        return self


def run_sweep(truth, methods, config: SweepConfig, workdir: Path, progress=None) -> dict:
    """The sweep's results: ``cells`` (one per method, sigma and fraction, with its trials) and
    ``breakdown`` (:func:`recon_eval.sweep.summary.breakdown_points`). ``truth`` is the kind's
    (``kind.truth``; for F a :class:`recon_eval.tasks.fmatrix_pair.PairTruth` in undistorted pixels);
    ``workdir`` holds what external commands read and write."""
    config.check()
    kind = KINDS[config.kind]
    scores = {m.name: {} for m in methods}
    for i_s, sigma in enumerate(config.sigmas_px):
        for i_o, frac in enumerate(config.outlier_fractions):
            for k in range(config.trials):
                trial = kind.draw(truth, config.points, sigma, frac, config.seed, (i_s, i_o), k)
                mseed = seed32(config.seed, f"{kind.stream}-method", i_s, i_o, k)
                for m in methods:
                    est = kind.fit(m, trial, truth, mseed, Path(workdir) / m.name / f"s{i_s}_o{i_o}_t{k}")
                    scores[m.name].setdefault((sigma, frac), []).append(kind.score(est, trial, truth))
            if progress:
                progress(f"sigma {sigma:g} px, outliers {frac:g}: done")
    cells = []
    for m in methods:
        for (sigma, frac), trials in scores[m.name].items():
            cells.append({"method": m.name, "family": m.family, "sigma_px": sigma, "outlier_fraction": frac,
                          **kind.summarise(trials, config.breakdown), "trials": trials})
    return {"config": asdict(config), "error": error_of(kind), "cells": cells,
            "breakdown": breakdown_points(cells, config.breakdown, kind.cell_keys[2])}


def error_of(kind) -> dict:
    """What a sweep's cells report: the kind's measure, unit and cell keys (for the report)."""
    mean, std, median = kind.cell_keys
    return {"kind": kind.name, "label": kind.label, "measure": kind.measure, "unit": kind.unit, "mean_key": mean,
            "std_key": std, "median_key": median}
