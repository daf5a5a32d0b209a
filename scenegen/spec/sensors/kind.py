"""What a sensor kind is: :class:`SensorKind`, one entry of the registry
:data:`scenegen.spec.sensors.SENSOR_KINDS` (docs/architecture.md, "Add a sensor kind").

A rig holds sensors of several kinds, each member with its extrinsic ``rig_from_sensor`` and its
time offset; a frame is the rig at a time (:class:`RigFrame`), and a member samples at
``frame.time_s + member.time_offset_s`` with the pose ``world_from_rig(t) @ rig_from_sensor``.
A kind produces either views (one image and its per-pixel truth per member and frame, rendered by
the pipeline's view path: the camera) or a stream (timestamped samples in chunks beside the
views, :mod:`scenegen.dataset.streams`, written by the kind's own ``write``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

from scenegen.geometry.pose import Rigid3

#: What a kind produces: views (images + per-pixel truth, the pipeline's view path) or a stream.
VIEWS = "views"
STREAM = "stream"
#: ... or light: the views of its rig's cameras are rendered under it (a projector's patterns).
LIGHT = "light"
PRODUCTS = (VIEWS, STREAM, LIGHT)
#: The keys a rig member names its sensor and its pose with, for every kind.
MEMBER_KEYS = ("sensor", "rig_from_sensor")


def stream_name(view_set, member) -> str:
    """The stream a rig member of a stream kind writes for a view set: ``<view set>_<member>``
    (the view set's ``prefix``: its name, else its rig's)."""
    return f"{view_set.prefix}_{member.name}"


@dataclass(frozen=True, kw_only=True)
class RigFrame:
    """A rig at a time: one placement of a rig view set. ``time_s`` is seconds on the sequence
    clock (None for a view set without times: it is not a sequence); ``world_from_rig`` (metres)
    is the rig frame's pose at that time."""

    rig: str
    view_set: int  # index into SceneSpec.view_sets
    frame_index: int  # the placement counter of scenegen.spec.views (views of the frame share it)
    time_s: float | None
    world_from_rig: Rigid3


@dataclass(frozen=True, kw_only=True)
class SensorRun:
    """What a stream kind's ``write`` gets for one member of one rig view set: the spec, the
    member (:class:`scenegen.spec.model.RigMember`) and its sensor (the kind's model, from its
    section), the view set's frames in order, the stream name to write (``<view set>_<member>``),
    the dataset writer (``scenegen.dataset.DatasetWriter``: ``StreamWriter(writer, name,
    schema)``) and the loaded scene (``scenegen.render.LoadedScene``, for kinds that cast rays)."""

    spec: Any
    member: Any
    sensor: Any
    frames: tuple[RigFrame, ...]
    stream: str
    writer: Any
    scene: Any = None

    def sample_times_s(self) -> tuple[float, ...]:
        """The member's sample time at each frame: the frame's time plus its time offset (s)."""
        return tuple(f.time_s + self.member.time_offset_s for f in self.frames)


@dataclass(frozen=True, kw_only=True)
class SensorKind:
    """One sensor kind: its spec section, how its members sit in a rig, what it produces.

    ``section``: the top-level YAML key of its sensors (a mapping name -> sensor) and ``parse``
    ``(node, name, ctx) -> model`` one of them (a :class:`scenegen.spec.parse.context
    .ParseContext` that knows the render settings, materials and cameras); ``model`` the frozen
    dataclass it returns. ``spec_field``: the :class:`SceneSpec` attribute holding the section
    (``cameras`` for cameras), None = ``SceneSpec.sensors[name]``. ``member_keys``: the keys a rig
    member names its sensor and its pose with, besides ``sensor`` / ``rig_from_sensor`` (the
    camera's ``camera`` / ``rig_from_cam``), also the keys of the member in the resolved spec.
    ``time_offsets``: whether a member may sample off its rig's time. ``produces``: VIEWS,
    STREAM or LIGHT (the rig's views are rendered under it: :mod:`.projector`); ``truth``: what each output holds (the camera: the per-pixel truth keys; a stream:
    its field names). ``write(run: SensorRun)``: a stream kind's writer (None for views, which
    the pipeline renders). ``to_yaml(model) -> dict``: one sensor back to YAML (the camera's is
    ``scenegen.spec.to_yaml``'s own). ``check_view_set(member, sensor, view_set, node)``: a stream
    kind's rules on the view set its rig is placed by (``node`` its YAML node), raising a
    SpecError (e.g. the IMU's: a C2 trajectory); None = no rules beyond having times."""

    name: str
    section: str
    model: type
    parse: Callable[..., Any]
    produces: str
    truth: tuple[str, ...]
    spec_field: str | None = None
    member_keys: tuple[str, str] = MEMBER_KEYS
    time_offsets: bool = True
    write: Callable[[SensorRun], Any] | None = None
    to_yaml: Callable[[Any], dict] | None = None
    check_view_set: Callable[..., None] | None = None

    def __post_init__(self):
        if self.produces not in PRODUCTS:
            raise ValueError(f"sensor kind {self.name!r}: produces must be one of {PRODUCTS}, got {self.produces!r}")
        if (self.produces == STREAM) != (self.write is not None):
            raise ValueError(f"sensor kind {self.name!r}: a stream kind has a write function, a views kind none "
                             "(the pipeline renders views)")
        if self.spec_field is None and self.to_yaml is None:
            raise ValueError(f"sensor kind {self.name!r}: a section in SceneSpec.sensors needs to_yaml")

    def sensors_of(self, spec_or_ctx) -> Mapping[str, Any]:
        """{name: model} of this kind in a SceneSpec or a ParseContext."""
        if self.spec_field is not None:
            return getattr(spec_or_ctx, self.spec_field)
        return spec_or_ctx.sensors.get(self.name, {})
