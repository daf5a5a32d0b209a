"""Keypoint detectors and matches scored on exact, occlusion-aware dense correspondences.

The truth is a correspondence map of view i into view j (docs/crossview.md, "Dense
correspondences": ``corr/<i>/<j>.exr``, channels ``u``, ``v`` (pixels of j) and ``state`` per pixel
centre of i: 0 no surface, 1 visible, 2 occluded, 3 out of frame). A keypoint at a sub-pixel
position of i is carried into j by bilinear interpolation of (u, v) over the pixel centres around it;
it has truth only if every centre with a non-zero weight is ``visible`` (a keypoint exactly on a
pixel centre needs only that centre; one near an occlusion boundary or outside
[0, W - 1] x [0, H - 1] has none). This is the "region visible in both views", occlusion aware.

* Repeatability and localisation error (SuperPoint, DeTone et al. 2018, sec. 7.2 and their
  evaluation code), two definitions (:data:`REPEATABILITY_DEFINITIONS`):

  - ``all_keypoints`` (the default): keypoints of i with truth are mapped into j, keypoints of j
    with truth (through the j -> i map) into i; a mapped keypoint is *repeated* when the nearest
    keypoint of the other view lies within ``eps_px`` (``<=``), the nearest being searched among
    ALL keypoints of the other view (one without truth included, e.g. on an occlusion edge).
    repeatability = (repeated_i + repeated_j) / (n_i + n_j) over keypoints with truth;
    localisation error = mean distance to that nearest keypoint over the repeated ones.
  - ``superpoint``: the reference's (``compute_repeatability`` of rpautrat/SuperPoint,
    ``superpoint/evaluations/detector_evaluation.py``): both sets are first restricted to the
    shared region (keypoints with truth in the other view), and every distance is measured in
    view j, between the keypoints of i mapped into j and the restricted keypoints of j:
    count_i = mapped keypoints of i whose nearest restricted keypoint of j is within eps,
    count_j = restricted keypoints of j whose nearest mapped keypoint of i is within eps;
    repeatability = (count_i + count_j) / (n_i + n_j) (the reference's top-k selection by score is
    the caller's: pass the keypoints to score). Localisation error: the mean of those nearest
    distances within eps, both counts, in j.

  The two differ where the views' scales differ (the reference measures j's keypoints in j, the
  default in i) and for keypoints of the other view without truth (on an occlusion edge or just
  outside the shared region), which only the default can find as a nearest neighbour.
* Mean matching accuracy MMA@t (D2-Net, Dusmanu et al. 2019, HPatches protocol): for putative
  matches (x_i, x_j), the distance between the truth position of x_i in j and x_j; MMA@t = fraction
  of matches with distance ``<= t`` px, for t = 1..10, per image pair, then averaged over pairs
  (:func:`mean_over_pairs`). A match whose x_i has no truth in j (occluded, out of frame, no
  surface) is counted as wrong (distance inf) and reported in ``n_no_truth``: with exact
  occlusion there is no correct match for it. A pair with no match has MMA 0.
* Matching score (Mikolajczyk & Schmid, TPAMI 2005): correct matches divided by the smaller of
  the two keypoint counts with truth in the other view. A match is correct when its distance is
  ``<= eps_px`` and both its keypoints have truth (both lie in the region visible in both views,
  as the denominator's keypoints do; otherwise a perfect result scores above 1 where the j
  keypoint's interpolation support touches a pixel not visible in i).
* Precision and recall of putative matches against the truth (the family of Mikolajczyk & Schmid,
  TPAMI 2005, sec. 4.1: recall = correct matches / correspondences, 1 - precision = false / all
  matches), per keypoint of view i: a putative match is correct iff its truth distance is
  ``<= eps_px``; precision = correct / putative (0 without putative matches; at ``eps_px`` = t it
  equals MMA@t); a keypoint of i is *matchable* iff it has truth in j and some keypoint of j lies
  within ``eps_px`` (``<=``) of that truth position; recall = keypoints of i with at least one
  correct match / matchable keypoints of i (NaN when none is matchable). A keypoint with a correct
  match is matchable, so recall lies in [0, 1] whatever the matcher returns (duplicates included).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError
from scenegen.dataset.crossview import VISIBLE  # the dataset's one visibility truth

#: Repeatability definitions (module docstring); the first is the default.
REPEATABILITY_DEFINITIONS = ("all_keypoints", "superpoint")
#: Thresholds of MMA, pixels (D2-Net plots 1..10).
MMA_THRESHOLDS_PX = tuple(float(t) for t in range(1, 11))


@dataclass(frozen=True)
class CorrespondenceMap:
    """Truth map of view i into view j: ``uv`` (H, W, 2) float64 pixels of j, ``state`` (H, W),
    and optionally ``z`` (H, W) float64 metres, the depth in j of each pixel's point (NaN: none)."""

    uv: np.ndarray
    state: np.ndarray
    z: np.ndarray | None = None

    @classmethod
    def of(cls, correspondence) -> "CorrespondenceMap":
        """From a :class:`scenegen.dataset.crossview.Correspondence` (the dataset reader's)."""
        return cls(correspondence.uv, correspondence.state, correspondence.z)

    def __post_init__(self):
        uv = as_float_array(self.uv, "correspondence uv", (None, None, 2))
        st = np.asarray(self.state)
        if st.shape != uv.shape[:2]:
            raise InputError(f"correspondence state: expected shape {uv.shape[:2]}, got {st.shape}")
        object.__setattr__(self, "uv", uv)
        object.__setattr__(self, "state", st.astype(np.uint8))
        if self.z is not None:
            object.__setattr__(self, "z", as_float_array(self.z, "correspondence z", st.shape))


def map_keypoints(keypoints, cmap: CorrespondenceMap):
    """Truth positions in j (N, 2) of keypoints (N, 2) of i, and a mask (N,) of those with truth
    (module docstring). Positions without truth are NaN."""
    kp = as_float_array(keypoints, "keypoints", (None, 2))
    H, W = cmap.state.shape
    out = np.full(kp.shape, np.nan)
    ok = np.all(np.isfinite(kp), axis=1) & (kp[:, 0] >= 0) & (kp[:, 0] <= W - 1) & (kp[:, 1] >= 0) & (kp[:, 1] <= H - 1)
    x, y = kp[ok, 0], kp[ok, 1]
    x0 = np.minimum(np.floor(x).astype(np.int64), W - 1)
    y0 = np.minimum(np.floor(y).astype(np.int64), H - 1)
    fx, fy = x - x0, y - y0
    x1, y1 = np.minimum(x0 + 1, W - 1), np.minimum(y0 + 1, H - 1)
    acc = np.zeros((len(x), 2))
    good = np.ones(len(x), dtype=bool)
    for xi, yi, w in ((x0, y0, (1 - fx) * (1 - fy)), (x1, y0, fx * (1 - fy)),
                      (x0, y1, (1 - fx) * fy), (x1, y1, fx * fy)):
        need = w > 0
        good &= ~need | (cmap.state[yi, xi] == VISIBLE)
        acc += np.where(need[:, None], w[:, None] * cmap.uv[yi, xi], 0.0)
    good &= np.all(np.isfinite(acc), axis=1)
    idx = np.flatnonzero(ok)
    ok[idx[~good]] = False
    out[idx[good]] = acc[good]
    return out, ok


@dataclass(frozen=True)
class Repeatability:
    eps_px: float
    repeatability: float  # (repeated_i + repeated_j) / (n_i + n_j); NaN when no keypoint has truth
    localisation_err_px: float  # mean nearest distance over repeated keypoints; NaN if none
    n_i: int  # keypoints of i with truth in j
    n_j: int
    repeated_i: int
    repeated_j: int
    definition: str = REPEATABILITY_DEFINITIONS[0]  # which of REPEATABILITY_DEFINITIONS


def _nearest(points: np.ndarray, targets: np.ndarray) -> np.ndarray:
    if len(targets) == 0:
        return np.full(len(points), np.inf)
    return cKDTree(targets).query(points, k=1)[0] if len(points) else np.zeros(0)


def repeatability(kp_i, kp_j, map_ij: CorrespondenceMap, map_ji: CorrespondenceMap,
                  eps_px: float = 3.0, definition: str = REPEATABILITY_DEFINITIONS[0]) -> Repeatability:
    """Detector repeatability and localisation error of keypoints ``kp_i`` (N, 2) of view i and
    ``kp_j`` (M, 2) of view j (OpenCV pixels), by ``definition`` (``all_keypoints`` or
    ``superpoint``, module docstring)."""
    if definition not in REPEATABILITY_DEFINITIONS:
        raise InputError(f"repeatability definition must be one of {REPEATABILITY_DEFINITIONS}, got {definition!r}")
    kp_i = as_float_array(kp_i, "kp_i", (None, 2))
    kp_j = as_float_array(kp_j, "kp_j", (None, 2))
    mi, oki = map_keypoints(kp_i, map_ij)
    mj, okj = map_keypoints(kp_j, map_ji)
    if definition == "superpoint":  # both sets in the shared region, every distance in j
        a, b = mi[oki], kp_j[okj]
        di, dj = _nearest(a, b), _nearest(b, a)
    else:
        di = _nearest(mi[oki], kp_j[np.all(np.isfinite(kp_j), axis=1)])
        dj = _nearest(mj[okj], kp_i[np.all(np.isfinite(kp_i), axis=1)])
    ri, rj = di <= eps_px, dj <= eps_px
    n = int(oki.sum() + okj.sum())
    nrep = int(ri.sum() + rj.sum())
    rep = nrep / n if n else float("nan")
    loc = float((di[ri].sum() + dj[rj].sum()) / nrep) if nrep else float("nan")
    return Repeatability(float(eps_px), rep, loc, int(oki.sum()), int(okj.sum()), int(ri.sum()), int(rj.sum()),
                         definition)


@dataclass(frozen=True)
class MatchAccuracy:
    thresholds_px: tuple
    mma: np.ndarray  # (T,) fraction of matches with dist <= threshold
    n_matches: int
    n_no_truth: int  # matches whose x_i has no truth in j (counted wrong)
    dist_px: np.ndarray  # (M,) |truth(x_i) - x_j|, inf without truth


def match_accuracy(x_i, x_j, map_ij: CorrespondenceMap, thresholds_px=MMA_THRESHOLDS_PX) -> MatchAccuracy:
    """MMA of putative matches: pixels ``x_i`` (M, 2) of view i matched to ``x_j`` (M, 2) of j."""
    x_i = as_float_array(x_i, "matches x_i", (None, 2))
    x_j = as_float_array(x_j, "matches x_j", (None, 2))
    if len(x_i) != len(x_j):
        raise InputError(f"matches: {len(x_i)} points in view i but {len(x_j)} in view j")
    m, ok = map_keypoints(x_i, map_ij)
    d = np.full(len(x_i), np.inf)
    d[ok] = np.linalg.norm(m[ok] - x_j[ok], axis=1)
    d[~np.isfinite(d)] = np.inf
    th = tuple(float(t) for t in thresholds_px)
    mma = np.array([np.mean(d <= t) if len(d) else 0.0 for t in th])
    return MatchAccuracy(th, frozen(mma), len(d), int(np.sum(~ok)), frozen(d))


def mean_over_pairs(results) -> np.ndarray:
    """MMA curve averaged over image pairs (each pair weighs the same, as D2-Net)."""
    results = list(results)
    if not results:
        raise InputError("mean_over_pairs: no image pair")
    if len({r.thresholds_px for r in results}) != 1:
        raise InputError("mean_over_pairs: pairs scored at different thresholds")
    return np.mean([r.mma for r in results], axis=0)


@dataclass(frozen=True)
class MatchingScore:
    eps_px: float
    score: float  # n_correct / min(n_i, n_j); NaN if either has no keypoint with truth
    n_correct: int
    n_i: int
    n_j: int


def matching_score(kp_i, kp_j, matches, map_ij: CorrespondenceMap, map_ji: CorrespondenceMap,
                   eps_px: float = 3.0) -> MatchingScore:
    """Matching score of ``matches`` (M, 2) int indices (into kp_i, kp_j): correct matches (truth
    distance ``<= eps_px``, both keypoints with truth) over the smaller count of keypoints with
    truth in the other view."""
    kp_i = as_float_array(kp_i, "kp_i", (None, 2))
    kp_j = as_float_array(kp_j, "kp_j", (None, 2))
    mt = check_match_indices(matches, len(kp_i), len(kp_j))
    acc = match_accuracy(kp_i[mt[:, 0]], kp_j[mt[:, 1]], map_ij, (eps_px,))
    ok_i = map_keypoints(kp_i, map_ij)[1]
    ok_j = map_keypoints(kp_j, map_ji)[1]
    n_correct = int(np.sum((acc.dist_px <= eps_px) & ok_j[mt[:, 1]]))  # ok_i is implied by a finite distance
    n_i, n_j = int(ok_i.sum()), int(ok_j.sum())
    den = min(n_i, n_j)
    return MatchingScore(float(eps_px), n_correct / den if den else float("nan"), n_correct, n_i, n_j)


def check_match_indices(matches, n_i: int, n_j: int) -> np.ndarray:
    """(M, 2) int64 indices, checked against the keypoint counts."""
    mt = np.asarray(matches)
    if mt.size == 0:
        mt = np.zeros((0, 2), dtype=np.int64)
    if mt.ndim != 2 or mt.shape[1] != 2 or not np.issubdtype(mt.dtype, np.integer):
        raise InputError(f"matches: expected (M, 2) integer indices, got {mt.shape} {mt.dtype}")
    if len(mt) and (mt.min() < 0 or mt[:, 0].max() >= n_i or mt[:, 1].max() >= n_j):
        raise InputError("matches: index out of range of the keypoints")
    return mt.astype(np.int64)


@dataclass(frozen=True)
class MatchPrecisionRecall:
    eps_px: float
    precision: float  # n_correct / n_putative; 0 without putative matches
    recall: float  # n_i_recalled / n_i_matchable; NaN when no keypoint of i is matchable
    n_putative: int
    n_correct: int  # putative matches with truth distance <= eps_px
    n_i_recalled: int  # distinct keypoints of i with at least one correct match
    n_i_matchable: int  # keypoints of i with truth in j and a keypoint of j within eps_px of it


def match_precision_recall(kp_i, kp_j, matches, map_ij: CorrespondenceMap,
                           eps_px: float = 3.0) -> MatchPrecisionRecall:
    """Precision and recall of putative ``matches`` (M, 2) int indices into ``kp_i`` (N, 2) and
    ``kp_j`` (K, 2), OpenCV pixels, against the truth map i -> j (module docstring)."""
    kp_i = as_float_array(kp_i, "kp_i", (None, 2))
    kp_j = as_float_array(kp_j, "kp_j", (None, 2))
    mt = check_match_indices(matches, len(kp_i), len(kp_j))
    acc = match_accuracy(kp_i[mt[:, 0]], kp_j[mt[:, 1]], map_ij, (eps_px,))
    correct = acc.dist_px <= eps_px
    m, ok = map_keypoints(kp_i, map_ij)
    d = np.full(len(kp_i), np.inf)
    d[ok] = _nearest(m[ok], kp_j[np.all(np.isfinite(kp_j), axis=1)])
    n_matchable = int(np.sum(d <= eps_px))
    n_recalled = len(np.unique(mt[correct, 0]))
    n_put, n_cor = len(mt), int(correct.sum())
    return MatchPrecisionRecall(float(eps_px), n_cor / n_put if n_put else 0.0,
                                n_recalled / n_matchable if n_matchable else float("nan"),
                                n_put, n_cor, n_recalled, n_matchable)
