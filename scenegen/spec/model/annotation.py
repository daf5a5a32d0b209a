"""An object's recognition annotation (``objects[i].annotation``): the model it is an instance
of, its declared symmetries (as BOP's ``models_info.json``), named 3D keypoints and, on the root
of an articulated figure, its skeleton (docs/scene_spec.md, "Object annotations";
docs/dataset_format.md, "Object truth")."""
from __future__ import annotations

from dataclasses import dataclass

from scenegen.geometry.pose import Rigid3
from scenegen.spec.model.meta import param, part


@dataclass(frozen=True, kw_only=True)
class Keypoint:
    """A named point on the object, in its object frame (metres, the frame of ``transform``, its
    scale included), or picked by the index of a vertex of its mesh (resolved when its truth is
    computed: ``position_object_m`` is then None)."""

    name: str
    position_object_m: tuple[float, float, float] | None = None
    vertex: int | None = None


@dataclass(frozen=True, kw_only=True)
class ContinuousSymmetry:
    """A rotational symmetry about ``axis`` through ``offset_m`` (object frame), any angle:
    BOP's ``symmetries_continuous`` entry {axis, offset}."""

    axis: tuple[float, float, float] = param(unit="unit direction, object frame")
    offset_m: tuple[float, float, float] = param((0.0, 0.0, 0.0), unit="metres, object frame", key="offset")
    # a point on the axis


@dataclass(frozen=True, kw_only=True, eq=False)
class Annotation:
    """What makes an object an annotated instance (module docstring)."""

    model: str  # the model it is an instance of; objects sharing it share BOP's obj_id and
    # COCO's category (numbered 1.. in order of first appearance)
    symmetries_discrete: tuple[Rigid3, ...] = part((), unit="object_from_object transforms that "
                                                   "leave the model's look unchanged")
    symmetries_continuous: tuple[ContinuousSymmetry, ...] = part((), unit="rotation axes")
    keypoints: tuple[Keypoint, ...] = part((), unit="named points, object frame")
    skeleton: tuple[tuple[str, str], ...] = part((), unit="pairs of keypoint names of this object "
                                                 "and its descendants")
