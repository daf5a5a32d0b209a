"""The sweep kinds (``recon-eval sweep --kind``), by name: ``f`` (fundamental matrices, the survey's
measure; :mod:`.draw`, :mod:`.methods`, :mod:`.summary`), ``h``, ``e`` and ``triangulation``
(:mod:`.pair_kinds`) and ``pnp`` (:mod:`.pnp_kind`). Each declares its truth, its trials, its
methods and its error (:class:`recon_eval.sweep.kind.SweepKind`); :mod:`.run` sweeps any of them the
same way."""
from __future__ import annotations

from recon_eval.errors import InputError
from recon_eval.sweep.draw import draw_trial
from recon_eval.sweep.kind import SweepKind
from recon_eval.sweep.methods import all_survey, resolve
from recon_eval.sweep.pair_kinds import E_KIND, H_KIND, TRI_KIND
from recon_eval.sweep.pnp_kind import PNP_KIND
from recon_eval.sweep.summary import score_trial, summarise_cell
from recon_eval.tasks.fmatrix_pair import pair_truth


def _f_truth(ds, views, pool, obj=None):
    if obj is not None:
        raise InputError("--object: not for --kind f (its truth is the pair's stored correspondences)")
    return pair_truth(ds, *views, pixels="undistorted", max_points=pool)


def _f_draw(truth, n, sigma, frac, seed, cell, trial):
    return draw_trial(truth.x1, truth.x2, truth.size2, n, sigma, frac, seed, cell, trial)


F_KIND = SweepKind(
    "f", "fundamental matrix", "fmatrix-sweep", "mean and std of the distances of the noise-free truth points of each "
    "trial's inliers to the estimated epipolar lines, both images (docs/fmatrix_survey.md)", "epi_mean_px", "px",
    ("epi_mean_px", "epi_std_px", "median_trial_epi_px"), 8, 2.0, 2, _f_truth, _f_draw,
    lambda m, trial, truth, seed, wd: m.fit(trial.x1, trial.x2, seed, wd), score_trial, summarise_cell, resolve,
    all_survey, lambda truth: truth.notes)

KINDS: dict[str, SweepKind] = {k.name: k for k in (F_KIND, H_KIND, E_KIND, PNP_KIND, TRI_KIND)}
