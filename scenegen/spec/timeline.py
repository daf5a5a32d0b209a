"""A spec over time: where every object is, how fast it moves and whether it exists at a time
on the sequence clock (numpy only; the renderer and the truth both ask here).

``world_from_object(t) = world_from_parent(t) @ parent_from_object(t)`` (docs/scene_spec.md,
"Sequences"): parent_from_object is the object's trajectory, its joint, or its fixed ``rest``;
an object without a parent hangs from the world. A static object (no ``animation``) stays at its
``transform``. Poses are rigid (no scale): the scale of ``transform`` acts in the object frame.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry.clock import Composed, StaticTrajectory, Trajectory, as_times
from scenegen.geometry.optics import world_from_object_at
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.trajectory import MotionState


@dataclass(frozen=True, eq=False)
class ObjectState:
    """An object at one time: its motion (pose + world-frame derivatives) and whether it exists."""

    motion: MotionState
    present: bool

    @property
    def world_from_object(self) -> Rigid3:
        return self.motion.world_from_frame


class _Fixed(StaticTrajectory):
    """A fixed ``rest`` pose, also asked one time at a time (``state``)."""

    def state(self, t_s: float) -> MotionState:
        return MotionState.still(self.world_from_body)


def local_trajectory(animation):
    """The trajectory of parent_from_object (an object with ``.state(t) -> MotionState``)."""
    if animation.trajectory is not None:
        return animation.trajectory.trajectory()
    if animation.joint is not None:
        return animation.joint.trajectory(animation.rest)
    return _Fixed(animation.rest)


def is_animated(obj) -> bool:
    return getattr(obj, "animation", None) is not None


def present_at(obj, t_s: float) -> bool:
    """The object exists at ``t_s`` (inside its closed ``visible_s`` interval, or always)."""
    a = getattr(obj, "animation", None)
    if a is None or a.visible_s is None:
        return True
    return a.visible_s[0] <= t_s <= a.visible_s[1]


def object_states(objects, t_s: float, *, trajectories: dict | None = None) -> dict[str, ObjectState]:
    """{object name: :class:`ObjectState`} at ``t_s`` for every object, in spec order (a parent
    comes before its children). ``trajectories``: a cache {name: local trajectory} to reuse."""
    cache = {} if trajectories is None else trajectories
    out: dict[str, ObjectState] = {}
    for obj in objects:
        a = getattr(obj, "animation", None)
        if a is None:
            out[obj.name] = ObjectState(MotionState.still(obj.transform.world_from_object), True)
            continue
        if obj.name not in cache:
            cache[obj.name] = local_trajectory(a)
        local = cache[obj.name].state(float(t_s))
        state = out[a.parent].motion.compose(local) if a.parent is not None else local
        parent_present = out[a.parent].present if a.parent is not None else True
        out[obj.name] = ObjectState(state, parent_present and present_at(obj, t_s))
    return out


class Timeline:
    """Object states of a spec at any time, the local trajectories built once."""

    def __init__(self, spec):
        self.objects = tuple(spec.objects)
        self.sequence = getattr(spec, "sequence", None)
        self._cache: dict = {}

    @property
    def animated(self) -> tuple[str, ...]:
        """Names of the objects that move or appear/leave, in spec order."""
        return tuple(o.name for o in self.objects if is_animated(o))

    def states(self, t_s: float) -> dict[str, ObjectState]:
        return object_states(self.objects, t_s, trajectories=self._cache)

    def knot_times_s(self) -> np.ndarray:
        """(K,) sorted times at which some object's motion may have a velocity jump (its own or
        a parent's keyframes, :attr:`scenegen.geometry.trajectory.KeyframeTrajectory.knot_times_s`)."""
        times = [np.asarray(self._local(obj).knot_times_s, np.float64) for obj in self.objects if is_animated(obj)]
        return np.unique(np.concatenate(times)) if times else np.empty(0)

    def _local(self, obj):
        if obj.name not in self._cache:
            self._cache[obj.name] = local_trajectory(obj.animation)
        return self._cache[obj.name]

    def object_trajectory(self, name: str) -> Trajectory:
        """``world_from_object`` of object ``name`` as a :class:`scenegen.geometry.clock.Trajectory`
        (its local trajectory under its parents'; a static object's fixed ``transform``)."""
        obj = next(o for o in self.objects if o.name == name)
        if not is_animated(obj):
            motion = getattr(obj, "motion", None)  # a still spec's clock: 0 at each view's mid-exposure
            return (motion.object_trajectory(obj.transform.world_from_object) if moves_within_frame(obj)
                    else StaticTrajectory(obj.transform.world_from_object))
        local = self._local(obj)
        parent = obj.animation.parent
        return Composed(self.object_trajectory(parent), local) if parent is not None else local

    def presence_at(self, name: str, times_s) -> np.ndarray:
        """(N,) bool: object ``name`` (and each of its parents) exists at times (N,) seconds."""
        t = as_times(times_s)
        obj = next(o for o in self.objects if o.name == name)
        a = getattr(obj, "animation", None)
        own = np.ones(len(t), bool) if a is None or a.visible_s is None else \
            (a.visible_s[0] <= t) & (t <= a.visible_s[1])
        return own & self.presence_at(a.parent, t) if a is not None and a.parent is not None else own

    def object_moves_at_times(self, times_s) -> dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """{object id: ((N, 3, 3) R, (N, 3) t world_from_object, (N,) present)} of every object
        that moves (:func:`moves_within_frame`) at times (N,) seconds on the clock, one per ray
        (vectorised over the times)."""
        out = {}
        for o in self.objects:
            if moves_within_frame(o):
                R, t = self.object_trajectory(o.name).poses_at(times_s)
                out[o.object_id] = (R, t, self.presence_at(o.name, times_s))
        return out

    def poses_by_id(self, t_s: float) -> dict[int, tuple[Rigid3, bool]]:
        """{object id: (world_from_object, present)} at ``t_s``."""
        s = self.states(t_s)
        return {o.object_id: (s[o.name].world_from_object, s[o.name].present) for o in self.objects}


def moves_within_frame(obj) -> bool:
    """The object moves during one frame's exposure or readout: a sequence's animated object, or
    an object with a (non-zero) ``motion``."""
    motion = getattr(obj, "motion", None)
    return is_animated(obj) or (motion is not None and not motion.is_static)


def poses_within_frame(timeline: Timeline, time_s: float | None, taus_s) -> dict[int, tuple]:
    """{object id: ((n, 3, 3) R, (n, 3) t of world_from_object, (n,) bool present)} of every
    object that moves within a frame (:func:`moves_within_frame`), at ``taus_s`` (n,) seconds from
    the frame's time ``time_s`` (None: a static spec's view, whose ``motion`` objects move about
    their ``transform`` from mid-exposure)."""
    taus = np.asarray(taus_s, np.float64).reshape(-1)
    movers = [o for o in timeline.objects if moves_within_frame(o)]
    out = {o.object_id: (np.empty((len(taus), 3, 3)), np.empty((len(taus), 3)), np.ones(len(taus), bool))
           for o in movers}
    for k, tau in enumerate(taus):
        states = timeline.states(time_s + tau) if time_s is not None and any(map(is_animated, movers)) else {}
        for o in movers:
            R, t, present = out[o.object_id]
            if is_animated(o):
                st = states[o.name]
                pose, present[k] = st.world_from_object, st.present
            else:
                pose = world_from_object_at(o.transform.world_from_object, o.motion, float(tau))
            R[k], t[k] = pose.R, pose.t
    return out
