"""The ``features`` subcommand of ``recon-eval`` (registered in :mod:`recon_eval.cli.registry`).

::

    recon-eval features RESULT DATASET [--eps PX] [--pixel-origin center|corner] [--pairs all|I:J ...]
                       [--repeatability all_keypoints|superpoint]

RESULT holds ``keypoints/<view>.txt|.npy`` and ``matches/<view_i>__<view_j>.txt|.npy``
(:mod:`recon_eval.readers.features`); DATASET is a scenegen dataset with cross-view truth. Scores
per pair, per series and over all pairs (:mod:`recon_eval.tasks.feature_eval`, docs/features.md).
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from recon_eval.cli.common import stderr_progress
from recon_eval.cli.scored import scored
from recon_eval.metrics.features import REPEATABILITY_DEFINITIONS
from recon_eval.readers.features import read_feature_files
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure
from recon_eval.tasks.feature_eval import evaluate_features, headline_metrics, results_dict, select_pairs


def arguments(p) -> None:
    p.add_argument("result", help="result folder: keypoints/<view>.txt|.npy (rows x y [extra columns]) and "
                                  "matches/<view_i>__<view_j>.txt|.npy (rows index_i index_j)")
    p.add_argument("dataset", help="scenegen dataset with cross-view truth (crossview/index.json, corr/<i>/<j>.exr)")
    p.add_argument("--eps", type=float, default=3.0, metavar="PX",
                   help="correctness threshold of repeatability, matching score, precision, recall (px, <=; default 3)")
    p.add_argument("--pixel-origin", choices=["center", "corner"], default="center",
                   help="where the result puts (0, 0): the centre of the top-left pixel (OpenCV, default) or its "
                        "corner (COLMAP, VLFeat: 0.5 is subtracted on reading)")
    p.add_argument("--pairs", nargs="+", default=["all"], metavar="all|I:J",
                   help="pairs to score: all crossview pairs (default) or VIEW_I:VIEW_J ...")
    p.add_argument("--repeatability", choices=REPEATABILITY_DEFINITIONS, default=REPEATABILITY_DEFINITIONS[0],
                   help="all_keypoints (default): the nearest among all keypoints of the other view; superpoint: "
                        "SuperPoint's reference, both sets restricted to the shared region (docs/features.md)")


def score(a):
    ds = read_dataset(a.dataset)
    pairs = select_pairs(ds, a.pairs)
    files = read_feature_files(a.result, [], pairs, a.pixel_origin)
    ev = evaluate_features(ds, files.keypoints, files.matches, pairs, a.eps, a.repeatability,
                           progress=stderr_progress("feature pairs"))
    inputs = {"result": a.result, "dataset": a.dataset, "eps_px": a.eps, "pixel_origin": a.pixel_origin,
              "repeatability_definition": a.repeatability,
              "pairs": [f"{i}:{j}" for i, j in pairs],
              "files": {k: None if f is None else str(f) for k, f in files.files.items()}}
    return inputs, results_dict(ev, files), lambda: feature_figures(ev)


#: MMA thresholds (px) drawn against the series' variable.
FIGURE_MMA_PX = (1.0, 3.0, 5.0)


def feature_figures(ev) -> list:
    """HTML figures of a :class:`recon_eval.tasks.feature_eval.FeatureEvaluation`: MMA against the pixel
    threshold per series, then per series MMA@1/3/5 and repeatability against what the series
    varies (rotation angle, scale ratio, or the pair for illumination and other series)."""
    curves = {f"{s.series} ({s.n_pairs} pairs)": (s.thresholds_px, s.mma) for s in ev.series}
    if len(ev.series) > 1:
        curves["all pairs"] = (ev.overall.thresholds_px, ev.overall.mma)
    figs = [Figure("MMA vs threshold", plots.mma_curves_figure(curves, title="mean matching accuracy per series"),
                   "D2-Net / HPatches: fraction of putative matches within t px of the truth (<=), mean over pairs; "
                   "matches without truth count as wrong")]
    for s in ev.series:
        ps = [p for p in ev.pairs if p.description.series == s.series]
        d = [p.description for p in ps]
        ys = {f"MMA@{t:g}": [p.mma.mma[p.mma.thresholds_px.index(t)] for p in ps] for t in FIGURE_MMA_PX}
        ys[f"repeatability (eps {ev.eps_px:g} px)"] = [p.repeatability.repeatability for p in ps]
        if s.kind == "viewpoint":
            x, kw = [e.rotation_deg for e in d], {"xlabel": "relative rotation (deg)"}
        elif s.kind == "scale":
            x, kw = [e.scale_ratio for e in d], {"xlabel": "scale ratio (apparent size in j / in i)", "logx": True}
        else:
            x, kw = np.arange(len(d)), {"xlabel": "pair (view j)", "xticklabels": [e.j for e in d]}
        figs.append(Figure(f"Series {s.series} ({s.kind})",
                           plots.metric_vs_figure(x, ys, ylabel="fraction", title=f"series {s.series}: {s.kind}", **kw),
                           "per pair; a red x marks an undefined value (no keypoint with truth)"))
    return figs


def features_headline(a, results) -> dict:
    """``metrics`` of ``features --json``: the headline a features run gives the same numbers
    (:func:`recon_eval.tasks.feature_eval.headline_metrics`)."""
    series = tuple(v for k, v in results.items() if k.startswith("series."))
    return headline_metrics(SimpleNamespace(overall=results["overall"], series=series))


COMMANDS = {"features": scored(arguments, score, features_headline)}
