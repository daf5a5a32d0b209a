"""Keypoint detectors, descriptors and matchers scored per image pair of a scenegen dataset.

The pairs are those of ``crossview/index.json`` (pairs ``[i, j]``; docs/crossview.md), the truth
their dense correspondence maps ``crossview/corr/<i>/<j>.exr`` and ``<j>/<i>.exr``, read through the
dataset reader (:meth:`recon_eval.readers.scenegen_dataset.DatasetTruth.correspondence`). For each pair
the metrics of :mod:`recon_eval.metrics.features` (repeatability and localisation error, MMA@1..10,
matching score, precision and recall of the putative matches) are computed on the keypoints and
matches of the result (:mod:`recon_eval.readers.features`), and the pair is described from the
truth alone (:class:`PairDescription`): relative rotation, scale ratio, baseline, series, lighting.
Pairs are grouped by series (the view set of view j) and summarised per series and over all pairs
(:class:`SeriesSummary`). Definitions, operators and sources: docs/features.md.

Failures are scored, not dropped: a view without keypoints has 0 keypoints, a pair without matches
has MMA 0 and precision 0; in the means over pairs a value that is undefined for a pair (NaN:
repeatability with no keypoint having truth, matching score with none on one side, recall with no
matchable keypoint) counts as 0, and those pairs are counted in ``n_pairs_undefined``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import frozen
from recon_eval.errors import InputError
from recon_eval.metrics.features import (
    CorrespondenceMap,
    MatchAccuracy,
    MatchingScore,
    MatchPrecisionRecall,
    REPEATABILITY_DEFINITIONS,
    Repeatability,
    check_match_indices,
    match_accuracy,
    match_precision_recall,
    matching_score,
    mean_over_pairs,
    repeatability,
)
from scenegen.dataset.crossview import VISIBLE
from scenegen.dataset.layout import CROSSVIEW_INDEX, view_paths
from scenegen.geometry.rotation import rotation_angle_rad

#: Default correctness threshold (px) of repeatability, matching score, precision and recall:
#: SuperPoint's and D2-Net's 3 px (HPatches protocol).
DEFAULT_EPS_PX = 3.0
#: Series kinds (:func:`series_kind`): what a series varies, hence the x axis of its figures.
KINDS = ("illumination", "viewpoint", "scale", "other")
#: A series whose largest relative rotation reaches this angle is a viewpoint series (x axis:
#: rotation_deg). Below it a camera that only zooms or moves along its axis, whose relative
#: rotation is 0 up to the look-at construction, is not mistaken for one.
VIEWPOINT_MIN_DEG = 2.0
#: A series (not viewpoint) whose scale ratio leaves [1 / r, r] somewhere is a scale series.
SCALE_MIN_RATIO = 1.1
#: Trailing frame number of a view name (``tilt_0003`` -> series ``tilt``), the series fallback
#: when cameras.json has no ``view_set`` (docs/scene_spec.md, "View names").
_FRAME_SUFFIX = re.compile(r"_\d+$")


@dataclass(frozen=True)
class PairDescription:
    """What changes from view i to view j, from the truth alone."""

    i: str
    j: str
    series: str  # view_set of view j in cameras.json, else j's name without its _NNNN
    rotation_deg: float  # angle of R_j R_i^T (cam_j_from_world R times cam_i_from_world R^T)
    scale_ratio: float  # median over pixels of i visible in j of depth_z_i / z_j * fx_j / fx_i
    baseline_m: float  # distance between the two camera centres
    lighting_changed: bool | None  # the views' `lights` differ; None when cameras.json has none
    n_covisible_px: int  # pixels of i visible in j (the scale ratio's sample)


@dataclass(frozen=True)
class PairScore:
    description: PairDescription
    n_keypoints_i: int  # all keypoints of i, with or without truth
    n_keypoints_j: int
    repeatability: Repeatability
    mma: MatchAccuracy
    matching_score: MatchingScore
    matches: MatchPrecisionRecall


@dataclass(frozen=True)
class SeriesSummary:
    """Means over the pairs of one series (or of all pairs: series ``"all"``, kind ``"all"``)."""

    series: str
    kind: str  # one of KINDS (what the series varies), or "all"
    n_pairs: int
    pairs: tuple  # "i__j" of each pair, in dataset order
    thresholds_px: tuple
    mma: np.ndarray  # (T,) mean MMA curve over pairs (mean_over_pairs)
    repeatability: float  # mean over pairs
    localisation_err_px: float  # mean over every repeated keypoint of the pairs; NaN if none
    matching_score: float  # mean over pairs
    precision: float  # mean over pairs
    recall: float  # mean over pairs
    n_pairs_undefined: int  # pairs where a mean above took an undefined (NaN) value as 0


@dataclass(frozen=True)
class FeatureEvaluation:
    eps_px: float
    pairs: tuple  # PairScore per pair, dataset order
    series: tuple  # SeriesSummary per series, in order of first appearance
    overall: SeriesSummary


# --- pairs and their description ------------------------------------------------------------
def crossview_pairs(ds) -> list:
    """(i, j) of every pair of ``crossview/index.json``, in its order (NotApplicable without
    cross-view truth, InputError when it has no pair)."""
    pairs = list(ds.crossview_pairs())
    if not pairs:
        raise InputError(f"{ds.root / CROSSVIEW_INDEX}: pairs: empty (no pair has correspondence truth)")
    return pairs


def select_pairs(ds, specs=None) -> list:
    """Pairs to score: every crossview pair for ``None`` or ``["all"]``, else ``"i:j"`` strings,
    each a crossview pair in either direction (correspondences are stored both ways)."""
    pairs = crossview_pairs(ds)
    if not specs or list(specs) == ["all"]:
        return pairs
    known = set(pairs) | {(j, i) for i, j in pairs}
    if "all" in specs:
        raise InputError("--pairs: 'all' cannot be combined with VIEW_I:VIEW_J")
    out = []
    for s in specs:
        parts = str(s).split(":")
        if len(parts) != 2 or not all(parts):
            raise InputError(f"--pairs: expected 'all' or VIEW_I:VIEW_J, got {s!r}")
        if tuple(parts) not in known:
            raise InputError(f"--pairs {s}: ({parts[0]}, {parts[1]}) is not a pair of "
                             f"{ds.root / CROSSVIEW_INDEX} (pairs: "
                             f"{', '.join(f'{i}:{j}' for i, j in pairs[:8])}{' ...' if len(pairs) > 8 else ''})")
        out.append(tuple(parts))
    return list(dict.fromkeys(out))


def series_name(view: str, info: dict) -> str:
    """The series of a view: its ``view_set`` in cameras.json, else its name without ``_NNNN``."""
    vs = info.get("view_set")
    if vs is not None and vs != "":
        return str(vs)
    return _FRAME_SUFFIX.sub("", view)


def lighting_changed(info_i: dict, info_j: dict) -> bool | None:
    """Whether the ``lights`` of two cameras.json view entries differ; None when either has none."""
    if "lights" not in info_i or "lights" not in info_j:
        return None
    return info_i["lights"] != info_j["lights"]


def correspondence_map(ds, i: str, j: str) -> CorrespondenceMap:
    """The truth map of view i into view j (the dataset's correspondences i -> j)."""
    return CorrespondenceMap.of(ds.correspondence(i, j))


def describe_pair(ds, i: str, j: str, map_ij: CorrespondenceMap) -> PairDescription:
    """:class:`PairDescription` of views i, j of dataset ``ds`` (a DatasetTruth); ``map_ij`` with
    its ``z`` channel (the depth in j of each pixel's point)."""
    (ci, pi), (cj, pj) = ds.camera(i), ds.camera(j)
    j_from_i = pj @ pi.inverse()
    z_i = ds.depth(i)
    if map_ij.z is None or z_i.shape != map_ij.state.shape:
        raise InputError(f"{ds.root / view_paths(i)['truth']}: depth_z shape {z_i.shape} differs from the "
                         f"correspondence map's {map_ij.state.shape} (or the map has no z)")
    with np.errstate(invalid="ignore", divide="ignore"):
        r = z_i / map_ij.z * (cj.fx / ci.fx)  # apparent size in j over apparent size in i
    r = r[(map_ij.state == VISIBLE) & np.isfinite(r) & (r > 0)]
    info_i, info_j = ds.view_info(i), ds.view_info(j)
    return PairDescription(i, j, series_name(j, info_j), float(np.degrees(rotation_angle_rad(j_from_i.R))),
                           float(np.median(r)) if len(r) else float("nan"), float(np.linalg.norm(j_from_i.t)),
                           lighting_changed(info_i, info_j), int(len(r)))


# --- scoring ---------------------------------------------------------------------------------
def score_pair(kp_i, kp_j, matches, map_ij: CorrespondenceMap, map_ji: CorrespondenceMap,
               description: PairDescription, eps_px: float = DEFAULT_EPS_PX,
               repeatability_definition: str = REPEATABILITY_DEFINITIONS[0]) -> PairScore:
    """Every metric of one pair: keypoints ``kp_i`` (N, 2), ``kp_j`` (K, 2) OpenCV px, putative
    ``matches`` (M, 2) int indices (i -> j); repeatability by ``repeatability_definition``
    (:data:`recon_eval.metrics.features.REPEATABILITY_DEFINITIONS`)."""
    kp_i, kp_j = np.asarray(kp_i, np.float64).reshape(-1, 2), np.asarray(kp_j, np.float64).reshape(-1, 2)
    mt = check_match_indices(matches, len(kp_i), len(kp_j))
    return PairScore(description, len(kp_i), len(kp_j),
                     repeatability(kp_i, kp_j, map_ij, map_ji, eps_px, repeatability_definition),
                     match_accuracy(kp_i[mt[:, 0]], kp_j[mt[:, 1]], map_ij),
                     matching_score(kp_i, kp_j, mt, map_ij, map_ji, eps_px),
                     match_precision_recall(kp_i, kp_j, mt, map_ij, eps_px))


def series_kind(descriptions) -> str:
    """What a series varies (module constants): ``illumination`` if the lighting changed in every
    pair; else ``viewpoint`` if some rotation reaches VIEWPOINT_MIN_DEG; else ``scale`` if some
    scale ratio leaves [1/SCALE_MIN_RATIO, SCALE_MIN_RATIO]; else ``other``."""
    d = list(descriptions)
    if d and all(x.lighting_changed is True for x in d):
        return "illumination"
    if any(x.rotation_deg >= VIEWPOINT_MIN_DEG for x in d):
        return "viewpoint"
    if any(np.isfinite(x.scale_ratio) and abs(np.log(x.scale_ratio)) >= np.log(SCALE_MIN_RATIO) for x in d):
        return "scale"
    return "other"


def _mean_failed_zero(values) -> tuple[float, np.ndarray]:
    v = np.asarray(values, np.float64)
    bad = ~np.isfinite(v)
    return float(np.where(bad, 0.0, v).mean()), bad


def summarise(scores, series: str, kind: str | None = None) -> SeriesSummary:
    """:class:`SeriesSummary` of pair scores (one series, or all pairs)."""
    scores = list(scores)
    if not scores:
        raise InputError(f"series {series!r}: no pair")
    rep, b1 = _mean_failed_zero([s.repeatability.repeatability for s in scores])
    ms, b2 = _mean_failed_zero([s.matching_score.score for s in scores])
    rec, b3 = _mean_failed_zero([s.matches.recall for s in scores])
    prec = float(np.mean([s.matches.precision for s in scores]))
    n_rep = sum(s.repeatability.repeated_i + s.repeatability.repeated_j for s in scores)
    loc_sum = sum((s.repeatability.repeated_i + s.repeatability.repeated_j) * s.repeatability.localisation_err_px
                  for s in scores if s.repeatability.repeated_i + s.repeatability.repeated_j)
    return SeriesSummary(series, kind or series_kind(s.description for s in scores), len(scores),
                         tuple(f"{s.description.i}__{s.description.j}" for s in scores), scores[0].mma.thresholds_px,
                         frozen(mean_over_pairs([s.mma for s in scores])), rep,
                         float(loc_sum / n_rep) if n_rep else float("nan"), ms, prec, rec, int(np.sum(b1 | b2 | b3)))


def evaluate_features(ds, keypoints: dict, matches: dict, pairs, eps_px: float = DEFAULT_EPS_PX,
                      repeatability_definition: str = REPEATABILITY_DEFINITIONS[0],
                      progress=None) -> FeatureEvaluation:
    """Score ``keypoints`` (view -> (N, 2) OpenCV px; a missing view has none) and ``matches``
    ((i, j) -> (M, 2) int indices; a missing pair has none) on ``pairs`` of dataset ``ds``;
    ``progress(done, total)`` after each pair."""
    if not eps_px > 0:
        raise InputError(f"eps_px must be > 0, got {eps_px}")
    scores = []
    pairs = list(pairs)
    for n, (i, j) in enumerate(pairs):
        if progress is not None and n:
            progress(n, len(pairs))
        map_ij, map_ji = correspondence_map(ds, i, j), correspondence_map(ds, j, i)
        desc = describe_pair(ds, i, j, map_ij)
        none = np.zeros((0, 2))
        scores.append(score_pair(keypoints.get(i, none), keypoints.get(j, none),
                                 matches.get((i, j), np.zeros((0, 2), np.int64)), map_ij, map_ji, desc, eps_px,
                                 repeatability_definition))
    if progress is not None:
        progress(len(pairs), len(pairs))
    by_series: dict = {}
    for s in scores:
        by_series.setdefault(s.description.series, []).append(s)
    return FeatureEvaluation(float(eps_px), tuple(scores), tuple(summarise(v, k) for k, v in by_series.items()),
                             summarise(scores, "all", "all"))


# --- reporting -------------------------------------------------------------------------------
def _at(summary: SeriesSummary, t_px: float) -> float:
    return float(summary.mma[summary.thresholds_px.index(float(t_px))])


#: Thresholds (px) of the headline MMA metrics.
HEADLINE_MMA_PX = (1.0, 3.0, 5.0)


def headline_metrics(ev: FeatureEvaluation) -> dict:
    """Flat floats for gates and the leaderboard: ``mma_1``, ``mma_3``, ``mma_5``, ``repeatability``,
    ``localisation_err_px``, ``matching_score``, ``recall`` over all pairs, then per series
    ``<series>.mma_3``, ``.repeatability``, ``.matching_score``, ``.recall``. (Precision is MMA at
    eps by definition: it stays in the per-pair and series results, not among the headlines.)"""
    o = ev.overall
    m = {f"mma_{t:g}": _at(o, t) for t in HEADLINE_MMA_PX}
    m.update(repeatability=o.repeatability, localisation_err_px=o.localisation_err_px,
             matching_score=o.matching_score, recall=o.recall)
    for s in ev.series:
        m.update({f"{s.series}.mma_3": _at(s, 3.0), f"{s.series}.repeatability": s.repeatability,
                  f"{s.series}.matching_score": s.matching_score, f"{s.series}.recall": s.recall})
    return m


def results_dict(ev: FeatureEvaluation, files=None) -> dict:
    """Result groups of the JSON report: ``overall``, ``series.<name>``, ``pair.<i>__<j>``, and
    ``coverage`` (views without keypoints, pairs without matches, unused files) when ``files``
    (a :class:`recon_eval.readers.features.FeatureFiles`) is given."""
    res = {"overall": ev.overall}
    res.update({f"series.{s.series}": s for s in ev.series})
    res.update({f"pair.{p.description.i}__{p.description.j}": p for p in ev.pairs})
    if files is not None:
        res["coverage"] = {"n_views": len(files.keypoints),
                           "n_views_without_keypoints": len(files.views_without_keypoints),
                           "views_without_keypoints": list(files.views_without_keypoints),
                           "n_pairs": len(files.matches), "n_pairs_without_matches": len(files.pairs_without_matches),
                           "pairs_without_matches": list(files.pairs_without_matches),
                           "unused_files": list(files.unused_files)}
    return res
