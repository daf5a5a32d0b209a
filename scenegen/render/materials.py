"""Spec materials and textures -> Mitsuba BSDF dicts, one translation function per spec kind.

Texture UVs: Mitsuba's bitmap puts v = 0 at the image's top row, the project's convention, so
UVs pass through unchanged (checked in tests/scenegen/render/test_render.py).
"""
from __future__ import annotations

import mitsuba as mi
import numpy as np

from scenegen.assets.meshes import texture_image
from scenegen.assets.texture_files import load_data_image
from scenegen.geometry.conventions import opengl_from_directx_normal_map
from scenegen.spec import model as m

#: Board pictures are black/white; printed paper is neither 0 nor 1 in reflectance.
BOARD_BLACK, BOARD_WHITE = 0.03, 0.85


def rgb(c) -> dict:
    """A Mitsuba RGB spectrum value."""
    return {"type": "rgb", "value": [float(x) for x in c]}


def bitmap(img: np.ndarray, wrap_mode: str = "repeat") -> dict:
    """Linear float32 (H, W, 3) reflectance as a raw (non-sRGB) Mitsuba bitmap texture.

    Procedural textures tile seamlessly, so they repeat (no visible UV seam on spheres and tori);
    board pictures clamp, so no opposite edge bleeds into the board's border."""
    # a writable copy: mi.Bitmap takes no read-only array (cached textures are read-only)
    return {"type": "bitmap", "bitmap": mi.Bitmap(np.array(img, dtype=np.float32, order="C")),
            "raw": True, "filter_type": "bilinear", "wrap_mode": wrap_mode}


def value_bitmap(values: np.ndarray, filter_type: str = "bilinear") -> dict:
    """(H, W) float values (opacity, heights, roughness) as a raw one-channel bitmap texture."""
    a = np.array(values, dtype=np.float32, order="C")[..., None]
    return {"type": "bitmap", "bitmap": mi.Bitmap(a), "raw": True, "filter_type": filter_type,
            "wrap_mode": "repeat"}


def _reflectance(color, texture) -> dict:
    return bitmap(texture_image(texture)) if texture is not None else rgb(color)


def _diffuse(mat: m.DiffuseMaterial) -> dict:
    return {"type": "diffuse", "reflectance": _reflectance(mat.color, mat.texture)}


def _plastic(mat: m.PlasticMaterial) -> dict:
    refl = _reflectance(mat.color, mat.texture)
    if mat.roughness > 0:
        return {"type": "roughplastic", "diffuse_reflectance": refl, "alpha": float(mat.roughness),
                "int_ior": float(mat.ior), "distribution": "ggx"}
    return {"type": "plastic", "diffuse_reflectance": refl, "int_ior": float(mat.ior)}


def _conductor(mat: m.ConductorMaterial) -> dict:
    if mat.roughness > 0:
        return {"type": "roughconductor", "material": mat.material, "alpha": float(mat.roughness),
                "distribution": "ggx"}
    return {"type": "conductor", "material": mat.material}


def _dielectric(mat: m.DielectricMaterial) -> dict:
    d = {"type": "dielectric", "int_ior": float(mat.ior),
         "specular_transmittance": rgb(mat.transmittance)}
    if mat.roughness > 0:
        d.update({"type": "roughdielectric", "alpha": float(mat.roughness), "distribution": "ggx"})
    return d


def _thin_dielectric(mat: m.ThinDielectricMaterial) -> dict:
    return {"type": "thindielectric", "int_ior": float(mat.ior),
            "specular_transmittance": rgb(mat.transmittance)}


def _principled(mat: m.PrincipledMaterial) -> dict:
    d = {"type": "principled", "base_color": _reflectance(mat.color, mat.texture),
         "metallic": float(mat.metallic), "roughness": float(mat.roughness),
         "specular": float(mat.specular), "spec_trans": float(mat.spec_trans),
         "clearcoat": float(mat.clearcoat), "sheen": float(mat.sheen)}
    pbr = getattr(mat, "pbr_set", None)
    return d if pbr is None else with_pbr_set(d, pbr)


def with_pbr_set(bsdf: dict, pbr) -> dict:
    """A principled BSDF with a texture set's roughness and metallic maps (perceptual roughness,
    as Blender's), wrapped in its bump (disp) and normal maps (a DirectX map converted to OpenGL's
    +y up the image, :func:`scenegen.geometry.conventions.opengl_from_directx_normal_map`)."""
    for key, mp in (("roughness", pbr.roughness), ("metallic", pbr.metallic)):
        if mp is not None:
            bsdf[key] = value_bitmap(load_data_image(mp.path)[..., mp.channel])
    if pbr.disp is not None:
        bsdf = with_bump_map(bsdf, load_data_image(pbr.disp.path)[..., 0], pbr.disp_scale_m)
    if pbr.normal is not None:
        normals = load_data_image(pbr.normal.path)
        bsdf = with_normal_map(bsdf, opengl_from_directx_normal_map(normals) if pbr.normal.directx else normals)
    return bsdf


MATERIALS = {m.DiffuseMaterial: _diffuse, m.PlasticMaterial: _plastic, m.ConductorMaterial: _conductor,
             m.DielectricMaterial: _dielectric, m.ThinDielectricMaterial: _thin_dielectric,
             m.PrincipledMaterial: _principled}


def material_dict(mat) -> dict:
    """Mitsuba BSDF for a spec material, wrapped in its maps (bump, normal, then the alpha mask
    outermost)."""
    try:
        translate = MATERIALS[type(mat)]
    except KeyError:
        raise TypeError(f"unknown material {type(mat).__name__}") from None
    bsdf = translate(mat)
    maps = getattr(mat, "maps", None)
    if maps is None:
        return bsdf
    if maps.bump_map is not None:
        bsdf = with_bump_map(bsdf, _map_values(maps.bump_map)[..., 0], maps.bump_scale)
    if maps.normal_map is not None:
        bsdf = with_normal_map(bsdf, _map_values(maps.normal_map))
    if maps.alpha is not None:
        bsdf = with_alpha(bsdf, 1.0, _map_values(maps.alpha)[..., 0],
                          "blend" if maps.alpha_blend else "mask", maps.alpha_cutoff)
    return bsdf


def _map_values(texture) -> np.ndarray:
    """A map's values as data: an image file read without sRGB decoding, or a procedural
    texture's values; (H, W, 3) float32."""
    if texture.kind == "image":
        return load_data_image(texture.path)
    return texture_image(texture)


#: Opacity at or above which a texel is a surface for the truth rays (alpha masks).
OPAQUE_AT = 0.5


def with_normal_map(bsdf: dict, normals01: np.ndarray | None) -> dict:
    """Wrap in Mitsuba's ``normalmap``: values 2 c - 1 in the shading frame, +x along dP/du,
    +y = n x (+x) (UP the image for an unmirrored texture: the OpenGL and glTF convention), +z
    along n. Mitsuba also applies the bump-terminator shadowing of Estevez et al. 2019."""
    if normals01 is None:
        return bsdf
    return {"type": "normalmap", "normalmap": bitmap(np.asarray(normals01, dtype=np.float32)), "bsdf": bsdf}


def with_bump_map(bsdf: dict, heights: np.ndarray | None, scale: float) -> dict:
    """Wrap in Mitsuba's ``bumpmap`` (heights in [0, 1] x ``scale``, in UV units)."""
    if heights is None:
        return bsdf
    return {"type": "bumpmap", "bump": value_bitmap(heights), "scale": float(scale), "bsdf": bsdf}


def with_alpha(bsdf: dict, opacity: float, opacity_texture, mode: str, cutoff: float) -> dict:
    """Wrap in Mitsuba's ``mask``; 'opaque' or a fully opaque constant leaves it as is."""
    if mode == "opaque":
        return bsdf
    if opacity_texture is None:
        value = float(opacity >= cutoff) if mode == "mask" else float(opacity)
        if value >= 1.0:
            return bsdf
        return {"type": "mask", "opacity": {"type": "rgb", "value": [value] * 3}, "bsdf": bsdf}
    a = np.asarray(opacity_texture, dtype=np.float64) * float(opacity)
    if mode == "mask":
        tex = value_bitmap((a >= cutoff).astype(np.float32), filter_type="nearest")
    else:
        tex = value_bitmap(a.astype(np.float32))
    return {"type": "mask", "opacity": tex, "bsdf": bsdf}


def is_alpha_masked(bsdf: dict) -> bool:
    """Whether a BSDF dict is a ``mask`` (always the outermost wrapper, so that the truth rays
    can ask it its opacity: :mod:`scenegen.render.alpha`)."""
    return bsdf.get("type") == "mask"



def board_material(board) -> dict:
    """The printed board picture as a diffuse BSDF (reflectance BOARD_BLACK .. BOARD_WHITE)."""
    img = board.image.astype(np.float32) / 255.0
    refl = BOARD_BLACK + (BOARD_WHITE - BOARD_BLACK) * img
    return {"type": "diffuse", "reflectance": bitmap(np.repeat(refl[..., None], 3, axis=2), "clamp")}
