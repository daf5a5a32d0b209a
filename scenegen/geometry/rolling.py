"""Rolling shutter: rows as times, poses tabulated per image row, and where a rolling-shutter
camera images a point.

Row ``v`` (continuous, OpenCV pixel rows, 0 = top) of a frame is exposed around
``tau(v) = Shutter.row_times_s(v, H)`` seconds from the frame's time (its middle row at 0; the one
definition, :mod:`scenegen.geometry.optics`; the renderer's sensor times its samples by the same
line); :class:`RowClock` puts the rows on the sequence clock (:mod:`scenegen.geometry.clock`), so a
table is a trajectory evaluated at the row times (:meth:`RowPoses.of_trajectory`) and is read
by row or by time. Poses within a frame (the camera's ``world_from_cam``, a moving object's
``world_from_object``: a frame's rotation and its origin's path) are tabulated at the row
centres from one row above the image to one below, nodes ``v = -1 .. H``, plus a node (a knot)
at the row of every keyframe time that falls inside the frame's readout, where a path's velocity
may jump (a linear path's keyframes, the held pose before the first and after the last one): a
pixel row's own pose is a node, exactly; between nodes a pose is
interpolated along the geodesic (rotation ``R_k exp(a log(R_k^T R_k+1))``, translation linearly).
Nodes are at most one row time apart (e.g. 12 ms / 239 rows = 50 us), where a trajectory
accelerating at 10 m/s^2 leaves the chord by ``a dt^2 / 8`` = 3e-9 m; a linear (lerp/slerp) path
or a constant velocity is interpolated exactly, up to rounding, kinks included (without the knots
an interval straddling a kink would cut the corner: 0.19 mm on a 3.7 m/s path, issue 26).

A rolling-shutter camera sees a point where the row that images it is exposed: ``v`` solving
``v = row(project(cam_from_world(v) @ P(v)))``, with ``P(v)`` the point at that row's time (it
moves with its object). :func:`rolling_project` finds it by fixed-point iteration; it converges
when the point crosses fewer rows per row time than the shutter sweeps (the image moving less
than ``(H - 1) / readout`` px/s vertically), geometrically with that ratio. Rows are clamped to the
sensor's extent ``[-0.5, H - 0.5]``: a point imaged beyond it is out of frame, and its position
is the projection at the edge row's time.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from scenegen.geometry.rotation import matrix_from_rotvec, rotvec_from_matrix

#: A fixed point is reached when the row moves by less than this between iterations (pixels).
ROW_TOL_PX = 1e-9
#: Iterations before a point counts as having no consistent row (it outruns the shutter's sweep).
MAX_ITERATIONS = 60


@dataclass(frozen=True)
class RowClock:
    """A frame's image rows on the clock: row ``v`` (continuous) is exposed at
    ``frame_time_s + shutter.row_times_s(v, height)`` seconds (:class:`~scenegen.geometry.optics.Shutter`;
    ``frame_time_s`` the middle row's time: a sequence frame's ``time_s``, 0 for a still spec)."""

    shutter: object  # scenegen.geometry.optics.Shutter
    height: int
    frame_time_s: float = 0.0

    def times_s(self, rows) -> np.ndarray:
        """(N,) times (seconds on the clock) of rows (N,)."""
        return self.frame_time_s + self.shutter.row_times_s(np.asarray(rows, np.float64), self.height)

    def rows(self, times_s) -> np.ndarray:
        """(N,) rows exposed at times (N,) seconds on the clock (the inverse of :meth:`times_s`)."""
        return self.shutter.rows_of_times_s(np.asarray(times_s, np.float64) - self.frame_time_s, self.height)


@dataclass(frozen=True, eq=False)
class RowPoses:
    """Rigid poses at the row nodes of one frame: ``first_row + k`` (k = 0 .. n-1), or the
    strictly increasing rows ``node_rows`` (n,) (uniform nodes with knots, module docstring).

    ``R`` (n, 3, 3), ``t`` (n, 3): the pose (x_from_y, any pair of frames) at each node.
    ``clock`` (:class:`RowClock`, optional): the rows' times, so the table is read by time
    (:meth:`poses_at`): a trajectory evaluated at the shutter's row times (:meth:`of_trajectory`)."""

    R: np.ndarray
    t: np.ndarray
    first_row: float = -1.0
    node_rows: np.ndarray | None = None
    clock: RowClock | None = None

    @classmethod
    def of_trajectory(cls, trajectory, clock: RowClock, node_rows) -> RowPoses:
        """``trajectory`` (:class:`scenegen.geometry.clock.Trajectory`, world_from_x) evaluated at
        the times of rows ``node_rows`` (n,): each node's pose is the trajectory's, exactly."""
        rows = np.asarray(node_rows, np.float64)
        R, t = trajectory.poses_at(clock.times_s(rows))
        return cls(R, t, node_rows=rows, clock=clock)

    def __post_init__(self):
        R, t = np.asarray(self.R, np.float64), np.asarray(self.t, np.float64)
        if R.ndim != 3 or R.shape[1:] != (3, 3) or t.shape != (len(R), 3) or len(R) < 2:
            raise ValueError(f"RowPoses: need (n, 3, 3) rotations and (n, 3) translations, n >= 2; "
                             f"got {R.shape} and {t.shape}")
        rows = (self.first_row + np.arange(len(R), dtype=np.float64) if self.node_rows is None
                else np.asarray(self.node_rows, np.float64))
        if rows.shape != (len(R),) or np.any(np.diff(rows) <= 0):
            raise ValueError(f"RowPoses: node_rows must be {len(R)} strictly increasing rows")
        object.__setattr__(self, "R", R)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "first_row", float(rows[0]))
        object.__setattr__(self, "node_rows", rows)
        # node positions from the first; integers for uniform nodes, so that the interval
        # arithmetic below is the plain floor/fraction of a uniform table
        object.__setattr__(self, "_f", rows - rows[0])
        # the geodesic step of each interval, in the frame of its first node
        object.__setattr__(self, "_w", rotvec_from_matrix(np.swapaxes(R[:-1], 1, 2) @ R[1:]))
        # the nodes' times: a time computed from a node's row by the same clock lands on it exactly
        object.__setattr__(self, "_times", None if self.clock is None else self.clock.times_s(rows))

    def interval(self, v) -> tuple[np.ndarray, np.ndarray]:
        """((N,) node index k, (N,) fraction a in [0, 1]) of rows ``v`` (N,): v lies between nodes
        k and k + 1 (rows beyond the nodes are clamped to the end nodes)."""
        f = np.clip(np.asarray(v, np.float64) - self.first_row, 0.0, self._f[-1])
        k = np.minimum(np.searchsorted(self._f, f, side="right") - 1, len(self._f) - 2)
        return k, (f - self._f[k]) / (self._f[k + 1] - self._f[k])

    def _interval_at_times(self, times_s) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`interval` of times (N,) seconds on the clock, the fraction taken in time."""
        if self._times is None:
            raise ValueError("RowPoses: reading poses by time needs the rows' clock (RowClock)")
        T = self._times
        if T[-1] == T[0]:  # a global shutter: every row at the frame time
            raise ValueError("RowPoses: a table over rows all exposed at one time cannot be read by time")
        f = np.clip(np.asarray(times_s, np.float64).reshape(-1), T[0], T[-1])
        k = np.minimum(np.searchsorted(T, f, side="right") - 1, len(T) - 2)
        return k, (f - T[k]) / (T[k + 1] - T[k])

    def poses_at(self, times_s) -> tuple[np.ndarray, np.ndarray]:
        """((N, 3, 3), (N, 3)) the poses at times (N,) seconds on the clock (:meth:`at` by time;
        a node's own time gives its pose exactly)."""
        return self._interpolate(*self._interval_at_times(times_s))

    def nearest_node(self, v) -> np.ndarray:
        """(N,) index of the node nearest to each of rows ``v`` (N,) (a tie: the lower node)."""
        k, a = self.interval(v)
        return k + (a > 0.5)

    def at(self, v) -> tuple[np.ndarray, np.ndarray]:
        """((N, 3, 3), (N, 3)) the poses at rows ``v`` (N,), interpolated between the nodes
        (module docstring); rows beyond the nodes take the end nodes' poses."""
        return self._interpolate(*self.interval(v))

    def _interpolate(self, k, a) -> tuple[np.ndarray, np.ndarray]:
        R = self.R[k] @ matrix_from_rotvec(a[:, None] * self._w[k]).reshape(-1, 3, 3)
        t = self.t[k] + a[:, None] * (self.t[k + 1] - self.t[k])
        return R, t


def frame_node_rows(shutter, height: int, knot_taus_s) -> np.ndarray:
    """(n,) the node rows of a rolling-shutter frame: -1 .. H, plus the rows of ``knot_taus_s``
    (seconds from the frame time; module docstring) that lie strictly inside and are no node yet."""
    rows = np.arange(-1, height + 1, dtype=np.float64)
    knots = shutter.row_of_time(np.asarray(knot_taus_s, np.float64), height)
    knots = knots[(knots > rows[0]) & (knots < rows[-1]) & (knots != np.round(knots))]
    return np.union1d(rows, knots)


@dataclass(frozen=True)
class RollingProjection:
    """Where a rolling-shutter camera images points: (N, 2) ``uv`` pixels, (N,) ``z`` depth in the
    camera at the imaging row (metres), (N,) ``valid`` (a projection exists, the row converged),
    (N,) ``row`` the row whose time the point is imaged at (clamped to the sensor), (N, 3)
    ``points_world`` where the point is then; (N,) ``converged`` False where no consistent row
    was found (uv NaN, not valid)."""

    uv: np.ndarray
    z: np.ndarray
    valid: np.ndarray
    row: np.ndarray
    points_world: np.ndarray
    converged: np.ndarray


def rolling_project(camera, world_from_cam: RowPoses,
                    points_at: Callable[[np.ndarray, np.ndarray], np.ndarray], n: int,
                    row_tol_px: float = ROW_TOL_PX, max_iterations: int = MAX_ITERATIONS) -> RollingProjection:
    """Image ``n`` points with a rolling-shutter ``camera`` whose ``world_from_cam`` per row is
    ``world_from_cam``. ``points_at(indices (M,), rows (M,)) -> (M, 3)`` gives the world position of
    points ``indices`` at the times of ``rows`` (static points ignore the rows). Fixed-point
    iteration from the middle row (module docstring)."""
    H = camera.height
    lo, hi = -0.5, H - 0.5
    v = np.full(n, 0.5 * (H - 1))
    uv = np.full((n, 2), np.nan)
    z = np.full(n, np.nan)
    P_out = np.full((n, 3), np.nan)
    valid = np.zeros(n, bool)
    done = np.zeros(n, bool)
    todo = np.arange(n)
    for _ in range(max_iterations):
        if not len(todo):
            break
        rows = v[todo]
        P = np.asarray(points_at(todo, rows), np.float64)
        R, C = world_from_cam.at(rows)
        P_cam = np.einsum("nji,nj->ni", R, P - C)  # R^T (P - C)
        uv_t, ok = camera.project(P_cam, return_valid=True)
        nxt = np.clip(uv_t[:, 1], lo, hi)
        # no projection (behind the camera, beyond the model's field): the row cannot move on
        settled = ~ok | ~np.isfinite(nxt) | (np.abs(nxt - rows) <= row_tol_px)
        fin = todo[settled]
        uv[fin], z[fin], P_out[fin], valid[fin], done[fin] = \
            uv_t[settled], P_cam[settled, 2], P[settled], ok[settled], True
        v[todo[~settled]] = nxt[~settled]
        todo = todo[~settled]
    converged = done
    uv[~converged] = np.nan
    return RollingProjection(uv, z, valid & converged, v, P_out, converged)


@dataclass(frozen=True, eq=False)
class RollingRows:
    """A rolling-shutter frame in which something moves: the camera's ``world_from_cam`` and
    every moving object's ``world_from_object`` (object id -> :class:`RowPoses`, with ``present``
    (n,) per node) at the frame's row nodes (:func:`frame_node_rows`, the same for all)."""

    cam: RowPoses
    objects: dict
    present: dict
    clock: RowClock | None = None  # the rows' times (then moves can be asked by time)

    @property
    def height(self) -> int:
        return int(self.cam.node_rows[-1])  # the last node is row H

    def pixel_rows(self) -> np.ndarray:
        """The node indices of the image's rows 0 .. H-1."""
        return np.searchsorted(self.cam.node_rows, np.arange(self.height, dtype=np.float64))

    def object_moves(self, rows=None) -> dict:
        """{object id: ((N, 3, 3) R, (N, 3) t world_from_object, (N,) present)} at ``rows`` (N,)
        (interpolated; present at the nearest node), or at the image's rows 0 .. H-1 (exact)."""
        if rows is None:
            k = self.pixel_rows()
            return {oid: (rp.R[k], rp.t[k], self.present[oid][k]) for oid, rp in self.objects.items()}
        return {oid: self.object_pose(oid, rows) for oid in self.objects}

    def object_moves_at_times(self, times_s) -> dict:
        """{object id: ((N, 3, 3) R, (N, 3) t world_from_object, (N,) present)} at times (N,)
        seconds on the clock (a ray's own time: its row's, a beam's, an event's), interpolated in
        time between the row nodes; present at the nearest node."""
        out = {}
        for oid, rp in self.objects.items():
            k, a = rp._interval_at_times(times_s)
            out[oid] = (*rp._interpolate(k, a), self.present[oid][k + (a > 0.5)])
        return out

    def object_pose(self, object_id: int, rows) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """((N, 3, 3) R, (N, 3) t world_from_object, (N,) present) of one moving object at
        ``rows`` (N,): interpolated; present at the nearest node."""
        rows = np.asarray(rows, np.float64)
        return (*self.objects[object_id].at(rows), self.present[object_id][self.cam.nearest_node(rows)])
