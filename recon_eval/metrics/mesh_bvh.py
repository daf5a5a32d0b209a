"""A bounding-volume hierarchy over triangles for exact point-to-mesh distances, in numpy.

The triangles are grouped by size class (box extents within a factor :data:`SIZE_CLASS`), and
for each class an implicit binary tree of axis-aligned boxes is built by median splits along the
longest axis of the centroids, down to leaves of :data:`LEAF` triangles. Separate classes keep a
few large triangles (a floor quad) from inflating the boxes of the small ones around them.

A query descends each tree :data:`STEP` levels at a time for a batch of points at once, keeping
the (point, node) pairs whose box can still hold the nearest triangle: a node is dropped when its
box is farther than an upper bound of the point's distance (the distance to the triangle of the
nearest centroid, tightened at every level by the farthest corner of a box, which bounds the
distance to every triangle inside it). At the leaves a triangle is dropped when its bounding disc
is farther than the bound, and the exact float64 point-to-triangle distance (Ericson 2005, sec.
5.1.5) of every remaining one is taken and the smallest kept. Nothing is
approximated: every triangle that could be nearest is examined, so the distance is the exact
minimum over all triangles (up to the rounding of Ericson's formula).

Memory is bounded for any triangle sizes: points go through in chunks, and a chunk whose set of
surviving pairs grows past :data:`MAX_PAIRS` is split in halves (down to single points), so a
mesh whose large triangles overlap every point costs time, never unbounded memory.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.spatial import cKDTree

LEAF = 4  # triangles per leaf
STEP = 3  # binary levels descended at once: 8 children per visited node
MAX_PAIRS = 2_000_000  # (point, node) or (point, triangle) pairs held at once per chunk
CHUNK = 65_536  # points per query batch
#: Relative slack on the pruning test so that a box exactly at the bound is never dropped by
#: rounding (box distances and bounds are computed in float64 from the same coordinates).
SLACK = 1e-9
SIZE_CLASS = 8.0  # triangles whose box extents differ by more than this go to different trees


def closest_points_on_triangles(p, a, b, c) -> np.ndarray:
    """Closest point (K, 3) on triangle (a_k, b_k, c_k) to p_k; all inputs (K, 3).

    Ericson (2005) sec. 5.1.5, ``ClosestPtPointTriangle``, with the region tests applied in the
    book's order (earlier tests take priority). A zero-area triangle whose region tests leave NaN
    (two coincident vertices) gets the nearest point of its three edges, its whole point set.
    """
    ab, ac, ap = b - a, c - a, p - a
    bp, cp = p - b, p - c
    d1 = np.einsum("ij,ij->i", ab, ap)
    d2 = np.einsum("ij,ij->i", ac, ap)
    d3 = np.einsum("ij,ij->i", ab, bp)
    d4 = np.einsum("ij,ij->i", ac, bp)
    d5 = np.einsum("ij,ij->i", ab, cp)
    d6 = np.einsum("ij,ij->i", ac, cp)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = 1.0 / (va + vb + vc)
        out = a + ab * (vb * denom)[:, None] + ac * (vc * denom)[:, None]  # face interior
        # Later assignments override earlier ones: apply in reverse of Ericson's priority.
        w_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        m = (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0)
        out[m] = (b + (c - b) * w_bc[:, None])[m]
        w_ac = d2 / (d2 - d6)
        m = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
        out[m] = (a + ac * w_ac[:, None])[m]
        m = (d6 >= 0) & (d5 <= d6)
        out[m] = c[m]
        v_ab = d1 / (d1 - d3)
        m = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
        out[m] = (a + ab * v_ab[:, None])[m]
        m = (d3 >= 0) & (d4 <= d3)
        out[m] = b[m]
        m = (d1 <= 0) & (d2 <= 0)
        out[m] = a[m]
    bad = ~np.all(np.isfinite(out), axis=1)
    if np.any(bad):
        out[bad] = _closest_points_on_edges(p[bad], a[bad], b[bad], c[bad])
    return out


def _closest_points_on_edges(p, a, b, c) -> np.ndarray:
    """Closest point (K, 3) to p_k on the three edges of (a_k, b_k, c_k): the whole point set of a
    zero-area triangle (e.g. a = b: the segment ac, which Ericson's tests leave as NaN)."""
    best, best_d = None, None
    for s, e in ((a, b), (b, c), (c, a)):
        se = e - s
        ll = np.einsum("ij,ij->i", se, se)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(ll > 0, np.einsum("ij,ij->i", p - s, se) / ll, 0.0)
        q = s + se * np.clip(t, 0.0, 1.0)[:, None]
        d = np.einsum("ij,ij->i", p - q, p - q)
        if best is None:
            best, best_d = q, d
        else:
            closer = d < best_d
            best[closer], best_d[closer] = q[closer], d[closer]
    return best


def point_triangle_sq_distances(p, a, b, c) -> np.ndarray:
    """Squared distance (K,) from p_k to triangle (a_k, b_k, c_k), all (K, 3) float64, through
    :func:`closest_points_on_triangles`."""
    d = p - closest_points_on_triangles(p, a, b, c)
    return np.einsum("ij,ij->i", d, d)


def _box_sq_dist(p: np.ndarray, mid: np.ndarray, half: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(nearest, farthest) squared distances from points (K, 3) to the boxes of centres ``mid``
    and half extents ``half`` (K, 3): with c = |p - mid|, nearest = |max(c - half, 0)|,
    farthest = |c + half|. An empty box (half = -inf) is infinitely far."""
    c = np.abs(p - mid)
    near = np.maximum(c - half, 0.0)
    far = c + half
    return np.einsum("ij,ij->i", near, near), np.einsum("ij,ij->i", far, far)


def _segment_min(values: np.ndarray, owner: np.ndarray, n: int, init: np.ndarray) -> np.ndarray:
    """min(init[k], min of values whose owner is k); owner sorted ascending."""
    out = init.copy()
    if len(values):
        starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
        k = owner[starts]
        out[k] = np.minimum(out[k], np.minimum.reduceat(values, starts))
    return out


def _median_split_order(cen: np.ndarray, n_slots: int, depth: int) -> np.ndarray:
    """Slot order (n_slots,) of triangle indices (-1 = empty) such that every aligned block of
    n_slots / 2^k slots (k <= depth) is a node of a binary tree whose split is at the median of its
    centroids along their longest axis (a partition, ``np.argpartition``, per node; empty slots
    sort last)."""
    F = len(cen)
    idx = np.full(n_slots, -1, dtype=np.int64)
    idx[:F] = np.arange(F)
    c = np.full((n_slots, 3), np.inf)
    c[:F] = cen
    for level in range(depth):
        nseg, size = 1 << level, n_slots >> level
        cs = c.reshape(nseg, size, 3)
        fin = np.isfinite(cs)
        ext = np.where(fin, cs, -np.inf).max(axis=1) - np.where(fin, cs, np.inf).min(axis=1)
        axis = np.argmax(np.where(np.isfinite(ext), ext, -1.0), axis=1)
        key = np.take_along_axis(cs, axis[:, None, None], axis=2)[:, :, 0]
        part = np.argpartition(key, size // 2 - 1, axis=1) if size > 1 else np.zeros((nseg, 1), np.int64)
        idx = np.take_along_axis(idx.reshape(nseg, size), part, axis=1).reshape(-1)
        c = np.take_along_axis(cs, part[:, :, None], axis=1).reshape(-1, 3)
    return idx


class _Tree:
    """A binary tree of boxes over the triangles ``ids`` (indices into the mesh's), traversed
    :data:`STEP` levels at a time (a 2^STEP-ary tree)."""

    def __init__(self, ids: np.ndarray, lo: np.ndarray, hi: np.ndarray, cen: np.ndarray):
        n_leaves = -(-len(ids) // LEAF)
        self.depth = max(1, int(np.ceil(np.log2(max(n_leaves, 2)) - 1e-12)))  # binary levels
        n_slots = (1 << self.depth) * LEAF
        slot = _median_split_order(cen[ids], n_slots, self.depth)
        used = slot >= 0
        self.tri_of_slot = np.where(used, ids[slot.clip(0)], -1)  # mesh triangle of each leaf slot, -1 empty
        slo = np.full((n_slots, 3), np.inf)
        shi = np.full((n_slots, 3), -np.inf)
        slo[used], shi[used] = lo[self.tri_of_slot[used]], hi[self.tri_of_slot[used]]
        blo, bhi = slo.reshape(-1, LEAF, 3).min(axis=1), shi.reshape(-1, LEAF, 3).max(axis=1)
        levels = [(blo, bhi)]
        while len(blo) > 1:
            blo, bhi = blo.reshape(-1, 2, 3).min(axis=1), bhi.reshape(-1, 2, 3).max(axis=1)
            levels.append((blo, bhi))
        # mid[l], half[l]: (2**l, 3) box centres and half extents of binary level l (0 = root); an
        # empty box gets mid 0 and half -inf, so its nearest distance is inf and it is never kept
        with np.errstate(invalid="ignore"):
            self.mid = [np.where(np.isfinite(a), 0.5 * (a + b), 0.0) for a, b in levels[::-1]]
            self.half = [np.where(np.isfinite(a), 0.5 * (b - a), -np.inf) for a, b in levels[::-1]]
        r = self.depth % STEP
        self.steps = list(range(r if r else STEP, self.depth + 1, STEP))  # binary levels visited


class TriangleBVH:
    """Exact nearest-triangle distances over triangles ``tri`` (F, 3, 3) float64 (see the module
    docstring): one tree per size class (box extents within a factor :data:`SIZE_CLASS` of each
    other), so that large triangles do not inflate the boxes of small ones."""

    def __init__(self, tri: np.ndarray):
        self.tri = tri = np.ascontiguousarray(tri, dtype=np.float64)
        lo, hi = tri.min(axis=1), tri.max(axis=1)
        cen = tri.mean(axis=1)
        # bounding disc of each triangle (centroid, farthest vertex, unit normal; a degenerate
        # triangle has normal 0 and its disc bound is the bounding sphere's): a cheap lower bound
        self._cen = cen
        self._rad = np.sqrt(np.max(np.sum((tri - cen[:, None, :]) ** 2, axis=2), axis=1)) * (1 + SLACK)
        nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        ln = np.linalg.norm(nrm, axis=1, keepdims=True)
        self._nrm = np.divide(nrm, ln, out=np.zeros_like(nrm), where=ln > 1e-300)
        size = np.max(hi - lo, axis=1)
        ref = max(float(np.median(size)), 1e-300)
        cls = np.floor(np.log(np.maximum(size, ref) / ref) / np.log(SIZE_CLASS)).astype(np.int64)
        self.trees = [_Tree(np.flatnonzero(cls == k), lo, hi, cen) for k in np.unique(cls)]
        self._centroid_tree = cKDTree(cen, balanced_tree=False, compact_nodes=False)

    def __len__(self) -> int:
        return len(self.tri)

    def sq_distances(self, points: np.ndarray, *, chunk: int = CHUNK,
                     progress: Callable[[int, int], None] | None = None) -> np.ndarray:
        """Exact squared distance (N,) from each point (N, 3) to the nearest triangle; points in
        batches of ``chunk``, ``progress(done, total)`` after each."""
        p = np.ascontiguousarray(points, dtype=np.float64)
        out = np.empty(len(p))
        for s in range(0, len(p), chunk):
            q = p[s:s + chunk]
            ub = self._upper_bounds(q)
            for tree in self.trees:
                ub = self._query(tree, q, ub)
            out[s:s + chunk] = ub
            if progress is not None:
                progress(min(s + chunk, len(p)), len(p))
        return out

    def _upper_bounds(self, p: np.ndarray) -> np.ndarray:
        """Squared distance to the triangle of the nearest centroid: an upper bound per point."""
        _, j = self._centroid_tree.query(p, k=1, workers=-1)
        t = self.tri[j]
        return point_triangle_sq_distances(p, t[:, 0], t[:, 1], t[:, 2])

    def _query(self, tree: _Tree, p: np.ndarray, ub: np.ndarray) -> np.ndarray:
        """min(ub, exact squared distance to the tree's triangles), points p (n, 3); ub is an
        upper bound of the distance to the mesh (the distance to some triangle) or larger."""
        n = len(p)
        owner = np.arange(n)
        node = np.zeros(n, dtype=np.int64)
        prev = 0
        for level in tree.steps:
            fan, prev = 1 << (level - prev), level
            owner = np.repeat(owner, fan)
            node = np.repeat(node, fan) * fan + np.tile(np.arange(fan), len(node))
            if len(owner) > MAX_PAIRS and n > 1:
                return self._split(tree, p, ub)
            near, far = _box_sq_dist(p[owner], tree.mid[level][node], tree.half[level][node])
            ub = _segment_min(far, owner, n, ub)
            keep = near <= ub[owner] * (1 + SLACK)
            owner, node = owner[keep], node[keep]
        owner = np.repeat(owner, LEAF)  # every triangle slot of the surviving leaves
        tri_idx = tree.tri_of_slot[np.repeat(node, LEAF) * LEAF + np.tile(np.arange(LEAF), len(node))]
        ok = tri_idx >= 0
        owner, tri_idx = owner[ok], tri_idx[ok]
        if len(owner) > MAX_PAIRS and n > 1:
            return self._split(tree, p, ub)
        # lower bound: the distance to the triangle's bounding disc, sqrt(h^2 + max(rho - r, 0)^2)
        # (h: height over its plane, rho: distance of the foot from the centroid); only the
        # triangles that can beat the upper bound go through Ericson's test
        pc = p[owner] - self._cen[tri_idx]
        h = np.einsum("ij,ij->i", pc, self._nrm[tri_idx])
        rho = np.sqrt(np.maximum(np.einsum("ij,ij->i", pc, pc) - h * h, 0.0))
        bound = h * h + np.maximum(rho - self._rad[tri_idx], 0.0) ** 2
        keep = bound <= ub[owner] * (1 + 1e-6)
        owner, tri_idx = owner[keep], tri_idx[keep]
        t = self.tri[tri_idx]
        d = point_triangle_sq_distances(p[owner], t[:, 0], t[:, 1], t[:, 2])
        return _segment_min(d, owner, n, ub)

    def _split(self, tree: _Tree, p: np.ndarray, ub: np.ndarray) -> np.ndarray:
        h = len(p) // 2
        return np.r_[self._query(tree, p[:h], ub[:h]), self._query(tree, p[h:], ub[h:])]
