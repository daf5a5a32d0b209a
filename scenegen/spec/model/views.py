"""View sets (placements of a camera or of a rig's frame) and resolved views."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Union

from scenegen.errors import Where
from scenegen.geometry.pose import Rigid3
from scenegen.spec.model.meta import SEED_MAX, WORLD_UP, param, part, where_field
from scenegen.spec.model.limits import MAX_VIEWS

_M = "metres"
_POS_M = dict(unit=_M, lo=0.0, lo_open=True)
_COUNT = dict(unit="views", label="", lo=1, hi=MAX_VIEWS)
_UP = dict(unit="direction")  # world direction shown up in the image
_SEED = dict(unit="seed", label="", lo=0, hi=SEED_MAX, derived="seed32(scene seed, field path)")


@dataclass(frozen=True, kw_only=True)
class Orbit:
    center: tuple[float, float, float] = param((0.0, 0.0, 0.0), unit=_M)  # point looked at
    radius_m: float = param(**_POS_M)  # distance from center to the eye
    elevations_deg: tuple[float, ...] = param((30.0,), unit="degrees", lo=-90.0, lo_open=True,
                                              hi=90.0, hi_open=True)  # above the xy plane
    # through center
    count: int = param(**_COUNT)  # views per elevation, evenly spaced in azimuth
    start_azimuth_deg: float = param(0.0, unit="degrees")  # azimuth of the first view, from +x
    # toward +y
    kind: str = field(default="orbit", init=False)


@dataclass(frozen=True, kw_only=True)
class LookAt:
    eye: tuple[float, float, float] = param(unit=_M)  # world
    target: tuple[float, float, float] = param(unit=_M)  # world
    up: tuple[float, float, float] = param(WORLD_UP, **_UP)


@dataclass(frozen=True, kw_only=True)
class LookAtList:
    entries: tuple[LookAt, ...]
    kind: str = field(default="look_at", init=False)


@dataclass(frozen=True, kw_only=True, eq=False)
class PoseList:
    world_from_cam: tuple[Rigid3, ...]  # camera (or, for a rig view set, rig) to world
    kind: str = field(default="poses", init=False)


@dataclass(frozen=True, kw_only=True)
class RandomPoses:
    count: int = param(**_COUNT)  # number of views
    seed: int = param(**_SEED)
    eye_min: tuple[float, float, float] = param(unit=_M, key="eye_box.min")  # eye box corner
    eye_max: tuple[float, float, float] = param(unit=_M, key="eye_box.max")
    target_min: tuple[float, float, float] = param(unit=_M, key="target_box.min")  # target box
    # (min == max for a fixed target: YAML `target`)
    target_max: tuple[float, float, float] = param(unit=_M, key="target_box.max")
    up: tuple[float, float, float] = param(WORLD_UP, **_UP)
    min_distance_m: float = param(0.0, unit=_M, lo=0.0)  # eye-target distances below this are
    # redrawn
    kind: str = field(default="random", init=False)


@dataclass(frozen=True, kw_only=True)
class LinePath:
    start: tuple[float, float, float] = param(unit=_M, key="line.from")  # first eye
    end: tuple[float, float, float] = param(unit=_M, key="line.to")  # last eye
    count: int = param(**_COUNT)  # eyes evenly spaced from start to end, both included
    target: tuple[float, float, float] = param(unit=_M)
    up: tuple[float, float, float] = param(WORLD_UP, **_UP)
    kind: str = field(default="line", init=False)


@dataclass(frozen=True, kw_only=True)
class CirclePath:
    center: tuple[float, float, float] = param((0.0, 0.0, 0.0), unit=_M, key="circle.center")
    radius_m: float = param(**_POS_M, key="circle.radius_m")
    height_m: float = param(0.0, unit=_M, key="circle.height_m")  # eyes at center + (r cos a,
    # r sin a, height_m)
    count: int = param(**_COUNT)  # eyes evenly spaced over 360 degrees (the start not repeated)
    start_azimuth_deg: float = param(0.0, unit="degrees", key="circle.start_azimuth_deg")  # from
    # +x toward +y
    target: tuple[float, float, float] = param(unit=_M, derived="center")
    up: tuple[float, float, float] = param(WORLD_UP, **_UP)
    kind: str = field(default="circle", init=False)


@dataclass(frozen=True, kw_only=True, eq=False)
class TrajectoryPath:
    """A camera (or rig frame) following keyframes over a sequence: one placement per frame."""

    trajectory: Any  # scenegen.spec.model.timeline.TrajectorySpec of world_from_cam / world_from_rig
    times_s: tuple[float, ...] = part(unit="seconds: the sequence's timestamps, one view per time")
    kind: str = field(default="trajectory", init=False)


Placement = Union[Orbit, LookAtList, PoseList, RandomPoses, LinePath, CirclePath, TrajectoryPath]


@dataclass(frozen=True, kw_only=True)
class ViewSet:
    name: str | None  # optional; prefix of the view names (default: camera or rig name)
    camera: str | None  # a key of `cameras:` (exactly one of camera / rig)
    rig: str | None  # a key of `rigs:`
    placement: Placement  # where the camera (or the rig frame) goes
    motion: Any = part(None, unit="scenegen.geometry.optics.Motion of the placed camera / rig "
                                  "frame (body velocities)")
    lights: Mapping[str, float] | None = param(None, unit="factor on the light's spec power",
                                               lo=0.0)  # illumination of this view set: every
    # spec light (spec order) -> factor on its spec power, 0 = off; None = every light at its power
    where: Where | None = where_field()

    @property
    def prefix(self) -> str:
        return self.name or self.camera or self.rig  # type: ignore[return-value]


@dataclass(frozen=True, kw_only=True, eq=False)
class View:
    """One image to render: a camera at a pose (resolved, not written in the YAML)."""

    name: str  # unique, e.g. 'left_0003' or 'stereo_right_0012' (see resolve_views)
    camera: str  # key of `cameras:`
    cam_from_world: Rigid3  # pose, metres
    rig: str | None = part(None, unit="rig name, or None for a lone camera")
    rig_member: str | None = part(None, unit="member name in the rig ('left', 'right', ...)")
    frame_index: int = part(0, unit="placement counter over all view sets; a rig's members "
                                    "share it")
    view_set: int = part(0, unit="index of the view set in `views:`")
    motion: Any = part(None, unit="scenegen.geometry.optics.Motion of this camera, in its own "
                                  "frame; None = static")
    light_scales: tuple[float, ...] | None = part(None, unit="factor on each spec light's power "
                                                  "(spec order; 0 = off); None = every light at "
                                                  "its spec power")
    time_s: float | None = part(None, unit="seconds on the sequence clock (a sequence frame); "
                                           "None = a static scene")
