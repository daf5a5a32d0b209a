"""Time: the sequence clock (the optional top-level ``sequence:`` section), keyframed
trajectories of cameras, rigs and objects, joints of articulated objects, and point-track
settings (docs/scene_spec.md, "Sequences"). The interpolation itself is
:mod:`scenegen.geometry.trajectory`; :mod:`scenegen.spec.timeline` evaluates a spec over time.
"""
from __future__ import annotations

from dataclasses import dataclass

from scenegen.errors import Where
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.trajectory import INTERPOLATIONS, JOINT_TYPES, JointTrajectory, KeyframeTrajectory
from scenegen.spec.model.limits import MAX_TRACKS
from scenegen.spec.model.meta import SEED_MAX, param, part, where_field

_S = "seconds"


@dataclass(frozen=True, kw_only=True, eq=False)
class Keyframe:
    time_s: float = param(unit=_S)  # on the sequence clock
    pose: Rigid3 = part(unit="world_from_X at time_s (X = camera, rig frame or object; for an "
                             "object with a parent: parent_from_object)")


@dataclass(frozen=True, kw_only=True, eq=False)
class TrajectorySpec:
    interpolation: str = param("spline", unit="interpolation", choices=INTERPOLATIONS)  # linear:
    # lerp + slerp; spline: C2 natural cubic (scenegen.geometry.trajectory)
    keyframes: tuple[Keyframe, ...] = part(unit="keyframes, strictly increasing time_s")
    where: Where | None = where_field()

    def trajectory(self) -> KeyframeTrajectory:
        return KeyframeTrajectory([k.time_s for k in self.keyframes], [k.pose for k in self.keyframes],
                                  self.interpolation)


@dataclass(frozen=True, kw_only=True)
class JointKeyframe:
    time_s: float = param(unit=_S)
    value: float = param(unit="radians (revolute, YAML angle_deg in degrees) or metres (prismatic, "
                              "YAML offset_m)")


@dataclass(frozen=True, kw_only=True, eq=False)
class JointSpec:
    """A joint between an object and its parent: parent_from_object(t) = J(q(t)) @ rest, rest =
    the object's ``transform`` (its placement in the parent frame at q = 0)."""

    type: str = param(unit="joint type", choices=JOINT_TYPES)
    axis: tuple[float, float, float] = param(unit="direction in the parent frame")
    origin: tuple[float, float, float] = param((0.0, 0.0, 0.0), unit="metres, parent frame")  # a
    # point on a revolute joint's axis
    interpolation: str = param("spline", unit="interpolation", choices=INTERPOLATIONS)
    keyframes: tuple[JointKeyframe, ...] = part(unit="joint values, strictly increasing time_s")
    where: Where | None = where_field()

    def trajectory(self, rest: Rigid3) -> JointTrajectory:
        return JointTrajectory(self.type, self.axis, self.origin, [k.time_s for k in self.keyframes],
                               [k.value for k in self.keyframes], self.interpolation, rest)


@dataclass(frozen=True, kw_only=True, eq=False)
class Animation:
    """How an object moves over a sequence. world_from_object(t) = world_from_parent(t) @
    parent_from_object(t): parent_from_object is the trajectory's pose, or the joint's, or the
    fixed ``rest``; without a parent, world_from_parent is the identity."""

    parent: str | None = param(None, unit="object name (defined earlier in `objects:`)")  # moves
    # with it as one rigid body (a tree of parts)
    trajectory: TrajectorySpec | None = part(None, unit="keyframes of parent_from_object")
    joint: JointSpec | None = part(None, unit="a joint to the parent")
    rest: Rigid3 = part(default_factory=Rigid3.identity, unit="parent_from_object as written in "
                        "`transform` (without a trajectory)")
    visible_s: tuple[float, float] | None = param(None, unit=_S)  # [appears, leaves]: the object
    # exists only in this closed interval; None = always


@dataclass(frozen=True, kw_only=True)
class TrackSpec:
    """Long point tracks (TAP-Vid style) per camera stream of a sequence."""

    count: int = param(256, unit="query points per stream", lo=1, hi=MAX_TRACKS)  # split between the query frames,
    # half on moving objects where any is seen
    query_frames: tuple[int, ...] = param((0,), unit="frame indices of the stream", lo=0)
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX,
                      derived="seed32(scene seed, field path)")
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class SequenceSpec:
    """The clock of a sequence: frame k of every camera stream is at ``timestamps_s[k]``."""

    fps: float | None = param(None, unit="frames / second", lo=0.0, lo_open=True)  # with frames
    frames: int | None = param(None, unit="frames", lo=1)  # with fps
    start_s: float = param(0.0, unit=_S)  # time of frame 0 (with fps)
    timestamps_s: tuple[float, ...] = param(unit=_S, derived="start_s + k / fps")  # or explicit,
    # strictly increasing
    flow_steps: tuple[int, ...] = param((1,), unit="frames", lo=1)  # flow, scene flow and
    # occlusion truth for frames (k, k + step) of each stream, both ways; each below the frame count
    tracks: TrackSpec | None = part(None, unit="point tracks; None = none")
    where: Where | None = where_field()
