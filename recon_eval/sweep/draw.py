"""One trial of a sweep cell: n truth correspondences drawn from a view pair's exact truth,
Gaussian noise on every coordinate, a fraction of them made outliers.

A pair trial (:func:`draw_trial`) draws, from ``scenegen.geometry.seeds.rng(seed, stream,
i_sigma, i_outlier, trial)`` (``stream``: the sweep kind's, ``fmatrix-sweep`` for F) and in this
order: the n rows of the truth (without replacement), the noise (n, 4) of
standard deviation sigma px on (x1, y1, x2, y2), the outlier rows (round(fraction n), without
replacement), and their image-2 points, uniform over image 2 ([-0.5, W - 0.5] x [-0.5, H - 0.5],
OpenCV pixel centres at integers). An outlier keeps its noisy x1 and loses its truth. Each cell's
stream depends on its indices only, never on what another cell drew.

A one-view trial (:func:`draw_view_trial`, PnP) draws the same way with noise (n, 2) on (x, y)
and the outliers' pixels uniform over that image: an outlier pixel loses its 3D truth point.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from scenegen.geometry.seeds import rng as derived_rng


@dataclass(frozen=True)
class Trial:
    """x1, x2 (n, 2): what the estimator gets (undistorted px); t1, t2 (n, 2): the noise-free truth
    of the same rows; inliers (n,) bool: False for the outliers (their t2 is not what x2 shows)."""

    x1: np.ndarray
    x2: np.ndarray
    t1: np.ndarray
    t2: np.ndarray
    inliers: np.ndarray
    rows: np.ndarray | None = None  # (n,) the drawn rows of the truth arrays


@dataclass(frozen=True)
class ViewTrial:
    """One view's trial: x (n, 2) what the estimator gets (undistorted px), t (n, 2) the noise-free
    truth pixels of the same rows, rows (n,) their indices in the truth arrays, inliers (n,) bool."""

    x: np.ndarray
    t: np.ndarray
    rows: np.ndarray
    inliers: np.ndarray


def _rows(g, m_all: int, n: int, what: str) -> np.ndarray:
    if m_all < n:
        raise InputError(f"sweep: the {what} has {m_all} visible truth points, fewer than --points {n}")
    return g.choice(m_all, n, replace=False)


def draw_trial(t1_all, t2_all, size2, n: int, sigma_px: float, outlier_fraction: float, seed: int,
               cell: tuple[int, int], trial: int, stream: str = "fmatrix-sweep") -> Trial:
    """The trial (module docstring) from truth correspondences t1_all <-> t2_all (M, 2), image 2 of
    ``size2`` (W, H); ``cell`` = (sigma index, outlier-fraction index)."""
    if len(t1_all) < n:
        raise InputError(f"sweep: the pair has {len(t1_all)} visible truth correspondences, fewer than --points {n}")
    g = derived_rng(seed, stream, cell[0], cell[1], trial)
    rows = g.choice(len(t1_all), n, replace=False)
    t1, t2 = t1_all[rows], t2_all[rows]
    noise = g.normal(0.0, 1.0, (n, 4)) * sigma_px
    x1, x2 = t1 + noise[:, :2], t2 + noise[:, 2:]
    m = int(round(outlier_fraction * n))
    out = g.choice(n, m, replace=False)
    w, h = size2
    x2[out] = g.uniform([-0.5, -0.5], [w - 0.5, h - 0.5], (m, 2))
    inliers = np.ones(n, bool)
    inliers[out] = False
    return Trial(x1, x2, t1, t2, inliers, rows)


def draw_view_trial(t_all, size, n: int, sigma_px: float, outlier_fraction: float, seed: int,
                    cell: tuple[int, int], trial: int, stream: str) -> ViewTrial:
    """The one-view trial (module docstring) from truth pixels t_all (M, 2) of an image of ``size``
    (W, H)."""
    g = derived_rng(seed, stream, cell[0], cell[1], trial)
    rows = _rows(g, len(t_all), n, "view")
    t = t_all[rows]
    x = t + g.normal(0.0, 1.0, (n, 2)) * sigma_px
    m = int(round(outlier_fraction * n))
    out = g.choice(n, m, replace=False)
    w, h = size
    x[out] = g.uniform([-0.5, -0.5], [w - 0.5, h - 0.5], (m, 2))
    inliers = np.ones(n, bool)
    inliers[out] = False
    return ViewTrial(x, t, rows, inliers)
