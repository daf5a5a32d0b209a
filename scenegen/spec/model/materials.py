"""Textures and materials (the ``materials:`` section and objects' inline materials)."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Union

from scenegen.errors import Where
from scenegen.spec.model.meta import SEED_MAX, frozen_mapping, param, part, where_field

TEXTURE_KINDS = ("image", "checkerboard", "noise", "speckle", "natural")
PROCEDURAL_TEXTURE_KINDS = TEXTURE_KINDS[1:]
MATERIAL_TYPES = ("diffuse", "plastic", "conductor", "dielectric", "thin_dielectric", "principled")
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
    kind: str = param(unit="texture type", choices=TEXTURE_KINDS, key="type")
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
class SurfaceMaps:
    """Maps any material may carry (the `normal_map`, `bump_map` and `alpha` keys)."""

    normal_map: Texture | None = part(None, unit="tangent-space normal map image (linear RGB, "
                                      "2c - 1; +x along u, +y along v = down the image)")
    bump_map: Texture | None = part(None, unit="height map (its first channel, in [0, 1])")
    bump_scale: float = param(1.0, unit="metres of displacement per unit of the map's value",
                              lo=0.0, lo_open=True)  # Mitsuba's bumpmap scale
    alpha: Texture | None = part(None, unit="opacity map (its first channel, in [0, 1])")
    alpha_cutoff: float = param(0.5, unit="opacity", lo=0.0, hi=1.0, lo_open=True)  # texels at
    # or above it are surface (opacity 1), below it holes (opacity 0)
    alpha_blend: bool = param(False, unit="flag")  # true: continuous opacity instead of the
    # cutoff (truth rays still take texels >= 0.5 as surface)
    where: Where | None = where_field()


_MAPS = dict(unit="normal map, bump map, alpha mask (None: none)", omit_default=True)


@dataclass(frozen=True, kw_only=True)
class PbrMap:
    """One data map of a texture set: an image and the channel that holds the value."""

    path: Path = part(unit="absolute path of the image (inside the set's folder)")
    path_as_written: str = part(unit="the file's name in the set's folder")
    channel: int = part(0, unit="channel index (0 R, 1 G, 2 B)")
    directx: bool = part(False, unit="flag: a DirectX normal map (+y down the image), converted to "
                                     "OpenGL's", omit_default=True)


@dataclass(frozen=True, kw_only=True)
class PbrSet:
    """A PBR texture set folder in Poly Haven's naming (scenegen.assets.pbr_sets): its diff map is
    the material's `texture`; roughness, metallic, normal and (with a scale) disp maps are here."""

    folder: str = part(unit="the folder as written (relative to the spec file)")
    name: str = param(unit="set name (the files' prefix)", derived="the folder's only set")
    resolution: str = param(unit="resolution tag, e.g. '1k'", derived="the set's only resolution")
    disp_scale_m: float | None = param(None, unit="metres of displacement per unit of the disp map",
                                       lo=0.0, lo_open=True)  # None: the disp map is not read
    roughness: PbrMap | None = part(None, unit="perceptual roughness map (rough, or arm's G)")
    metallic: PbrMap | None = part(None, unit="metallic map (metal, or arm's B)")
    normal: PbrMap | None = part(None, unit="tangent-space normal map (nor_gl, else nor_dx converted)")
    disp: PbrMap | None = part(None, unit="height map read as the bump map (with disp_scale_m)")
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class DiffuseMaterial:
    name: str | None = part(None, unit=_NAME)
    color: tuple[float, float, float] | None = param(_GREY, unit="linear RGB", lo=0.0, hi=1.0)
    # reflectance; None when `texture` is given
    texture: Texture | None = part(None, unit="reflectance texture (replaces color)")
    maps: SurfaceMaps | None = part(None, **_MAPS)
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
    maps: SurfaceMaps | None = part(None, **_MAPS)
    where: Where | None = where_field()
    type: str = field(default="plastic", init=False)


@dataclass(frozen=True, kw_only=True)
class ConductorMaterial:
    name: str | None = part(None, unit=_NAME)
    material: str = param("Al", unit="Mitsuba conductor name", label="a conductor name",
                          choices=CONDUCTOR_NAMES)  # e.g. 'Al', 'Cu', 'Au'
    roughness: float = param(0.1, unit="GGX alpha", lo=0.0)  # 0 = smooth mirror-like conductor
    maps: SurfaceMaps | None = part(None, **_MAPS)
    where: Where | None = where_field()
    type: str = field(default="conductor", init=False)


@dataclass(frozen=True, kw_only=True)
class DielectricMaterial:
    """Glass, water: a smooth (``dielectric``) or rough (``roughdielectric``) interface."""

    name: str | None = part(None, unit=_NAME)
    ior: float = param(1.5, unit="index of refraction", lo=1.0, lo_open=True)  # interior
    # (glass 1.5, water 1.333); the exterior is air (1.000277)
    roughness: float = param(0.0, unit="GGX alpha", lo=0.0)  # 0 = smooth (dielectric); > 0 =
    # roughdielectric (frosted glass)
    transmittance: tuple[float, float, float] = param((1.0, 1.0, 1.0), unit="linear RGB", lo=0.0,
                                                      hi=1.0, kind="color")  # specular transmittance (tint)
    maps: SurfaceMaps | None = part(None, **_MAPS)
    where: Where | None = where_field()
    type: str = field(default="dielectric", init=False)


@dataclass(frozen=True, kw_only=True)
class ThinDielectricMaterial:
    """A thin pane (window glass, a film of water): both interfaces in one surface, no offset."""

    name: str | None = part(None, unit=_NAME)
    ior: float = param(1.5, unit="index of refraction", lo=1.0, lo_open=True)
    transmittance: tuple[float, float, float] = param((1.0, 1.0, 1.0), unit="linear RGB", lo=0.0,
                                                      hi=1.0, kind="color")
    maps: SurfaceMaps | None = part(None, **_MAPS)
    where: Where | None = where_field()
    type: str = field(default="thin_dielectric", init=False)


@dataclass(frozen=True, kw_only=True)
class PrincipledMaterial:
    """Mitsuba's principled BSDF (Disney 2015); perceptual roughness (GGX alpha = roughness^2)."""

    name: str | None = part(None, unit=_NAME)
    color: tuple[float, float, float] | None = param(_GREY, unit="linear RGB", lo=0.0, hi=1.0)
    # base colour; None when `texture` is given
    texture: Texture | None = part(None, unit="base colour texture (replaces color)")
    metallic: float = param(0.0, unit="fraction", lo=0.0, hi=1.0)
    roughness: float = param(0.5, unit="perceptual roughness", lo=0.0, hi=1.0)
    specular: float = param(0.5, unit="Disney specular (0.5: F0 = 0.04, IOR 1.5)", label="",
                            lo=0.0, hi=1.0)
    spec_trans: float = param(0.0, unit="fraction", lo=0.0, hi=1.0)  # specular transmission
    # (1 = glass-like)
    clearcoat: float = param(0.0, unit="fraction", lo=0.0, hi=1.0)
    sheen: float = param(0.0, unit="fraction", lo=0.0, hi=1.0)
    maps: SurfaceMaps | None = part(None, **_MAPS)
    pbr_set: PbrSet | None = part(None, unit="a PBR texture set folder (Poly Haven naming) giving the "
                                  "texture and the roughness, metallic and normal maps", omit_default=True)
    where: Where | None = where_field()
    type: str = field(default="principled", init=False)


Material = Union[DiffuseMaterial, PlasticMaterial, ConductorMaterial, DielectricMaterial,
                 ThinDielectricMaterial, PrincipledMaterial]
