"""Textures and materials (the ``materials:`` section and objects' inline materials)."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Union

from scenegen.errors import Where
from scenegen.spec.model.meta import SEED_MAX, frozen_mapping, param, part, where_field

TEXTURE_KINDS = ("image", "checkerboard", "noise", "speckle", "natural")
PROCEDURAL_TEXTURE_KINDS = TEXTURE_KINDS[1:]
MATERIAL_TYPES = ("diffuse", "plastic", "conductor")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".exr", ".hdr", ".tif", ".tiff", ".bmp")
#: Conductor names Mitsuba 3 knows (its ``conductor``/``roughconductor`` ``material`` values).
CONDUCTOR_NAMES = (
    "none", "a-C", "Ag", "Al", "AlAs", "AlAs_palik", "AlSb", "AlSb_palik", "Au", "Be", "Be_palik",
    "Cr", "CsI", "CsI_palik", "Cu", "Cu_palik", "Cu2O", "Cu2O_palik", "CuO", "CuO_palik", "d-C",
    "d-C_palik", "Hg", "Hg_palik", "HgTe", "HgTe_palik", "Ir", "Ir_palik", "K", "K_palik", "Li",
    "Li_palik", "MgO", "MgO_palik", "Mo", "Mo_palik", "Na_palik", "Nb", "Nb_palik", "Ni_palik",
    "Rh", "Rh_palik", "Se", "Se_palik", "SiC", "SiC_palik", "SnTe", "SnTe_palik", "Ta",
    "Ta_palik", "Te", "Te_palik", "ThF4", "ThF4_palik", "TiC", "TiC_palik", "TiN", "TiN_palik",
    "TiO2", "TiO2_palik", "VC", "VC_palik", "V_palik", "VN", "VN_palik", "W", "W_palik",
)
_GREY = (0.5, 0.5, 0.5)
_NAME = "key under `materials:`; None for an inline material"


@dataclass(frozen=True, kw_only=True)
class Texture:
    kind: str = param(unit="texture type", choices=TEXTURE_KINDS)  # YAML `type`
    path: Path | None = part(None, unit="image file (absolute) for kind 'image'; None for "
                                         "procedural")
    path_as_written: str | None = part(None, unit="the path as in the spec (relative to the "
                                                   "spec file)")
    params: Mapping[str, Any] = part(default_factory=frozen_mapping, unit="procedural "
                                     "parameters")  # passed unchanged to
    # scenegen.assets.textures.make_texture(kind, params, seed); empty for 'image'
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX,
                      derived="seed32(scene seed, field path)")  # procedural seed
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class DiffuseMaterial:
    name: str | None = part(None, unit=_NAME)
    color: tuple[float, float, float] | None = param(_GREY, unit="linear RGB", lo=0.0, hi=1.0)
    # reflectance; None when `texture` is given
    texture: Texture | None = part(None, unit="reflectance texture (replaces color)")
    where: Where | None = where_field()
    type: str = field(default="diffuse", init=False)


@dataclass(frozen=True, kw_only=True)
class PlasticMaterial:
    name: str | None = part(None, unit=_NAME)
    color: tuple[float, float, float] | None = param(_GREY, unit="linear RGB", lo=0.0, hi=1.0)
    # diffuse reflectance; None when `texture` is given
    texture: Texture | None = part(None, unit="diffuse reflectance texture (replaces color)")
    roughness: float = param(0.1, unit="GGX alpha", lo=0.0)  # 0 = smooth plastic
    ior: float = param(1.49, unit="index of refraction", lo=1.0, lo_open=True)  # interior;
    # the exterior is air (1.000277)
    where: Where | None = where_field()
    type: str = field(default="plastic", init=False)


@dataclass(frozen=True, kw_only=True)
class ConductorMaterial:
    name: str | None = part(None, unit=_NAME)
    material: str = param("Al", unit="Mitsuba conductor name", label="a conductor name",
                          choices=CONDUCTOR_NAMES)  # e.g. 'Al', 'Cu', 'Au'
    roughness: float = param(0.1, unit="GGX alpha", lo=0.0)  # 0 = smooth mirror-like conductor
    where: Where | None = where_field()
    type: str = field(default="conductor", init=False)


Material = Union[DiffuseMaterial, PlasticMaterial, ConductorMaterial]
