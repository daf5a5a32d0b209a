"""The optional top-level ``variation:`` section: seeded ranges that make scene variants.

What is declared here is only ranges (parsed by :mod:`scenegen.spec.parse.variation`);
:func:`scenegen.spec.variants.derive_variant` draws one variant's values from
``(spec, seed, index)``. Documented in ``docs/scene_spec.md``.
"""
from __future__ import annotations

from dataclasses import dataclass

from scenegen.errors import Where
from scenegen.spec.model.meta import SEED_MAX, param, part, where_field

_M = "metres"


@dataclass(frozen=True, kw_only=True)
class ObjectVariation:
    object: str  # name of an object in `objects:`
    position_min: tuple[float, float, float] | None = param(None, unit=_M, key="position.min")
    # box of the object origin, world (replaces its translation)
    position_max: tuple[float, float, float] | None = param(None, unit=_M, key="position.max")
    yaw_deg: tuple[float, float] | None = param(None, unit="degrees", kind="range")  # range of
    # the turn about world +z through the origin
    color_min: tuple[float, float, float] | None = param(None, unit="linear RGB", lo=0.0, hi=1.0,
                                                         key="color.min")
    color_max: tuple[float, float, float] | None = param(None, unit="linear RGB", lo=0.0, hi=1.0,
                                                         key="color.max")
    # box of the material colour (diffuse/plastic with a colour only); YAML color: {min, max}
    reseed: bool = param(False, unit="flag")  # redraw the seeds of its procedural texture and
    # blob shape
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class LightVariation:
    light: str  # name of a light in `lights:`
    intensity_scale: tuple[float, float] | None = param(None, unit="factor", lo=0.0, kind="range")  # range of
    # the factor on radiance/intensity/scale
    position_jitter_m: float = param(0.0, unit=_M, lo=0.0)  # uniform offset in [-j, j] per world
    # axis (area/point/spot)
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class CameraVariation:
    camera: str  # name of a camera in `cameras:`
    focal_scale: tuple[float, float] | None = param(None, unit="factor", lo=0.0, lo_open=True,
                                                    kind="range")
    # range of one factor on fx and fy
    principal_point_px: float = param(0.0, unit="pixels", lo=0.0)  # uniform offset in [-j, j] on
    # cx and on cy
    dist_jitter: tuple[float, ...] = param((), unit="unitless", lo=0.0)  # uniform offset in
    # [-j_i, j_i] per coefficient (OpenCV order); as many values as the camera's `dist`
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class PoseJitter:
    """A rigid offset per placement (camera, or rig frame), in its own frame: uniform translation
    in [-t, t] per axis and a rotation about a uniform random axis by an angle uniform in [0, r]."""

    translation_m: float = param(0.0, unit=_M, lo=0.0)
    rotation_deg: float = param(0.0, unit="degrees", lo=0.0, hi=180.0)
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class VariationSpec:
    seed: int = param(unit="seed", label="", lo=0, hi=SEED_MAX,
                      derived="seed32(scene seed, 'variation')")
    objects: tuple[ObjectVariation, ...] = part((), unit="object variations, by object name")
    lights: tuple[LightVariation, ...] = part((), unit="light variations, by light name")
    cameras: tuple[CameraVariation, ...] = part((), unit="camera variations, by camera name")
    views: PoseJitter | None = part(None, unit="pose jitter of every placement")
    where: Where | None = where_field()
