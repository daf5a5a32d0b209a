"""Lights (radiance in W/(m^2 sr), intensity in W/sr, linear RGB)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

from scenegen.errors import Where
from scenegen.geometry.pose import Rigid3
from scenegen.spec.model.meta import param, part, where_field

LIGHT_TYPES = ("area", "point", "spot", "constant", "envmap", "directional")
#: A spot's default full-intensity half-angle, as a fraction of its cutoff.
BEAM_WIDTH_FRACTION = 0.75
_NAME = "name, unique among lights"
_DEFAULT_NAME = "'light<i>', i its position in `lights:`"
_RADIANCE = "linear RGB, W/(m^2 sr)"
_INTENSITY = "linear RGB, W/sr"


@dataclass(frozen=True, kw_only=True, eq=False)
class AreaLight:
    name: str | None = param(None, unit=_NAME, derived=_DEFAULT_NAME)  # None: set by the parser / Scene()
    size: tuple[float, float] = param((1.0, 1.0), unit="metres", lo=0.0, lo_open=True)
    # rectangle side lengths along the light's x and y
    world_from_light: Rigid3 = part(unit="the rectangle lies in the light's z = 0 plane and "
                                         "emits toward +z")
    radiance: tuple[float, float, float] = param(unit=_RADIANCE, lo=0.0, kind="color")  # emitted radiance
    where: Where | None = where_field()
    type: str = field(default="area", init=False)


@dataclass(frozen=True, kw_only=True)
class PointLight:
    name: str | None = param(None, unit=_NAME, derived=_DEFAULT_NAME)  # None: set by the parser / Scene()
    position: tuple[float, float, float] = param(unit="metres")  # world
    intensity: tuple[float, float, float] = param(unit=_INTENSITY, lo=0.0, kind="color")  # radiant intensity
    where: Where | None = where_field()
    type: str = field(default="point", init=False)


@dataclass(frozen=True, kw_only=True, eq=False)
class SpotLight:
    name: str | None = param(None, unit=_NAME, derived=_DEFAULT_NAME)  # None: set by the parser / Scene()
    position: tuple[float, float, float] = param(unit="metres")  # world
    target: tuple[float, float, float] = param(unit="metres")  # point the spot's axis passes
    # through, world
    world_from_light: Rigid3 = part(unit="light frame: origin at position, +z toward target")
    intensity: tuple[float, float, float] = param(unit=_INTENSITY, lo=0.0, kind="color")  # on-axis radiant
    # intensity
    cutoff_deg: float = param(20.0, unit="degrees", lo=0.0, lo_open=True, hi=90.0)  # half-angle
    # of the cone
    beam_width_deg: float = param(unit="degrees", lo=0.0, lo_open=True,
                                  derived=f"{BEAM_WIDTH_FRACTION:g} * cutoff_deg")  # half-angle
    # of full intensity, at most cutoff_deg
    where: Where | None = where_field()
    type: str = field(default="spot", init=False)


@dataclass(frozen=True, kw_only=True)
class ConstantLight:
    name: str | None = param(None, unit=_NAME, derived=_DEFAULT_NAME)  # None: set by the parser / Scene()
    radiance: tuple[float, float, float] = param(unit=_RADIANCE, lo=0.0, kind="color")  # uniform environment
    where: Where | None = where_field()
    type: str = field(default="constant", init=False)


@dataclass(frozen=True, kw_only=True)
class EnvmapLight:
    """Equirectangular image; its top row is world +z (up); turned by rotation_z_deg about +z."""

    name: str | None = param(None, unit=_NAME, derived=_DEFAULT_NAME)  # None: set by the parser / Scene()
    path: Path = part(unit="absolute path of the image (EXR/HDR preferred: linear radiance)")
    path_as_written: str = part(unit="the path as in the spec")
    scale: float = param(1.0, unit="radiance multiplier", label="", lo=0.0)
    rotation_z_deg: float = param(0.0, unit="degrees")  # turn about world +z
    where: Where | None = where_field()
    type: str = field(default="envmap", init=False)


@dataclass(frozen=True, kw_only=True)
class DirectionalLight:
    """A light at infinity (the sun, or photometric stereo's distant lights): parallel rays."""

    name: str = param(unit=_NAME, derived=_DEFAULT_NAME)
    direction_to_light: tuple[float, float, float] = param(unit="world direction from the scene "
                                                                "toward the light (any length "
                                                                "> 0)")
    irradiance: tuple[float, float, float] = param(unit="linear RGB, W/m^2 on a surface facing "
                                                        "the light", lo=0.0, kind="color")
    where: Where | None = where_field()
    type: str = field(default="directional", init=False)

    @property
    def unit_direction_to_light(self) -> tuple[float, float, float]:
        """``direction_to_light`` scaled to unit length."""
        n = math.sqrt(sum(float(x) ** 2 for x in self.direction_to_light))
        return tuple(float(x) / n for x in self.direction_to_light)  # type: ignore[return-value]


Light = Union[AreaLight, PointLight, SpotLight, ConstantLight, EnvmapLight, DirectionalLight]
