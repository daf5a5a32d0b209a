"""The exact truth the H, E, PnP and triangulation sweeps draw from (:mod:`recon_eval.sweep.kinds`):
truth points of the dataset and their pixels in one or two views.

The points are the dataset's stored world points (float32, read as float64) at pixel centres of
the first view; their pixels in every view are computed in float64 as UNDISTORTED OpenCV pixels
``K (X_c / Z_c)`` (the pixels F, E, H, solvePnP without distortion and triangulatePoints work in;
docs/metrics.md), so a pixel and its point agree to float64 rounding whatever the float32 storage
did to the point. A pair's points are those the second view sees (the dataset's ray-cast
visibility, :func:`recon_eval.tasks.triangulation_task.visible_truth_points`); a view's are its
valid pixel centres (:meth:`DatasetTruth.points_at_pixels`). Both are a seeded sample of at most
``pool`` points (seed 0: the truth does not move with the sweep's seed). With ``obj`` (``--object
NAME``) only the points whose first-view pixel sees that spec object are kept (the view's
``object_id`` truth at the point's pixel): a planar object of a larger scene for H, one object for
PnP.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.dlt import project_with_P
from recon_eval.metrics.triangulation import projection_matrix
from recon_eval.tasks.triangulation_task import visible_truth_points
from scenegen.geometry.twoview import ZERO_BASELINE_M


@dataclass(frozen=True)
class ViewsTruth:
    """Truth points X (M, 3) world metres and, per view, their undistorted pixels x (M, 2), the
    view's K (3, 3), cam_from_world (Rigid3), projection matrix P = K [R | t] (3, 4) and image
    size (W, H)."""

    views: tuple
    X: np.ndarray
    x: tuple
    K: tuple
    cam_from_world: tuple
    P: tuple
    sizes: tuple
    notes: dict

    @property
    def cam2_from_cam1(self):
        return self.cam_from_world[1] @ self.cam_from_world[0].inverse()


def _on_object(ds, view: str, X: np.ndarray, obj: str | None, how: str) -> tuple[np.ndarray, str]:
    """The rows of X (points at ``view``'s pixel centres) whose pixel sees the object ``obj``."""
    if obj is None:
        return X, how
    oid = ds.object_id(obj)
    cam, pose = ds.camera(view)
    uv = np.nan_to_num(np.asarray(cam.project(pose.apply(X)), np.float64), nan=-1.0)
    u, v = (np.clip(np.rint(uv[:, k]).astype(np.int64), 0, n - 1) for k, n in ((0, cam.width), (1, cam.height)))
    keep = ds.object_ids(view)[v, u] == oid
    if not keep.any():
        raise InputError(f"--object {obj}: no truth point of view {view!r} lies on it")
    return X[keep], f"{how}, on object {obj!r}"


def _build(ds, views: tuple, X: np.ndarray, how: str) -> ViewsTruth:
    cams = [ds.camera(v) for v in views]
    P = tuple(projection_matrix(c.K, p.R, p.t) for c, p in cams)
    x = tuple(project_with_P(Pv, X) for Pv in P)
    notes = {"views": list(views), "cameras": " / ".join(c.model for c, _ in cams), "points": f"{len(X)} {how}",
             "pixels": "undistorted: K (X_c / Z_c) of the truth points, float64"}
    return ViewsTruth(tuple(views), X, x, tuple(c.K for c, _ in cams), tuple(p for _, p in cams), P,
                      tuple((c.width, c.height) for c, _ in cams), notes)


def pair_points(ds, view1: str, view2: str, pool: int, obj: str | None = None, *, baseline: bool) -> ViewsTruth:
    """The truth of the pair ``view1 -> view2`` (module docstring); with ``baseline`` the two camera
    centres must differ (E and triangulation: no epipolar geometry, no depth otherwise)."""
    views = (ds.check_view(view1), ds.check_view(view2))
    if views[0] == views[1]:
        raise InputError(f"--views {view1} {view2}: the two views must differ")
    X = np.asarray(visible_truth_points(ds, *views, pool), np.float64)
    if len(X) == 0:
        raise InputError(f"{ds.root}: views {view1!r} and {view2!r} share no visible truth point")
    t = _build(ds, views, *_on_object(ds, views[0], X, obj, "truth points of view 1 that view 2 sees (seeded sample)"))
    if baseline and np.linalg.norm(t.cam2_from_cam1.t) < ZERO_BASELINE_M:
        raise InputError(f"{ds.root}: views {view1!r} and {view2!r} share one camera centre (zero baseline): "
                         "no relative translation and no depth to estimate")
    return t


def view_points(ds, view: str, pool: int, obj: str | None = None) -> ViewsTruth:
    """The truth of one view (module docstring)."""
    _, X = ds.points_at_pixels(ds.check_view(view), max_points=pool, seed=0)
    if len(X) == 0:
        raise InputError(f"{ds.root}: view {view!r} has no valid truth pixel")
    how = "truth points at the view's valid pixel centres (seeded sample)"
    return _build(ds, (view,), *_on_object(ds, view, np.asarray(X, np.float64), obj, how))


def plane_of(X_cam: np.ndarray, rel_tol: float) -> tuple[np.ndarray, float, float]:
    """``(n (3,), d, max residual m)`` of the least-squares plane ``n . X = d`` of points X_cam (M, 3)
    (SVD of the centred points); InputError when a point lies farther than ``rel_tol`` times the
    points' extent from it (not a planar scene)."""
    c = X_cam.mean(axis=0)
    _, _, Vt = np.linalg.svd(X_cam - c, full_matrices=False)
    n = Vt[2]
    res = float(np.max(np.abs((X_cam - c) @ n)))
    extent = float(np.max(np.linalg.norm(X_cam - c, axis=1)))
    if len(X_cam) < 4 or res > rel_tol * extent:
        raise InputError(f"sweep --kind h: the pair's truth points are not coplanar (max {res:.3g} m off their "
                         f"best plane, extent {extent:.3g} m): a homography sweep needs a planar scene, or "
                         "--object NAME of a planar object")
    return n, float(n @ c), res
