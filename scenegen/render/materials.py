"""Spec materials and textures -> Mitsuba BSDF dicts, one translation function per spec kind.

Texture UVs: Mitsuba's bitmap puts v = 0 at the image's top row, the project's convention, so
UVs pass through unchanged (checked in tests/scenegen/render/test_render.py).
"""
from __future__ import annotations

import mitsuba as mi
import numpy as np

from scenegen.assets.meshes import texture_image
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


MATERIALS = {m.DiffuseMaterial: _diffuse, m.PlasticMaterial: _plastic, m.ConductorMaterial: _conductor}


def material_dict(mat) -> dict:
    """Mitsuba BSDF for a spec material."""
    try:
        translate = MATERIALS[type(mat)]
    except KeyError:
        raise TypeError(f"unknown material {type(mat).__name__}") from None
    return translate(mat)


def board_material(board) -> dict:
    """The printed board picture as a diffuse BSDF (reflectance BOARD_BLACK .. BOARD_WHITE)."""
    img = board.image.astype(np.float32) / 255.0
    refl = BOARD_BLACK + (BOARD_WHITE - BOARD_BLACK) * img
    return {"type": "diffuse", "reflectance": bitmap(np.repeat(refl[..., None], 3, axis=2), "clamp")}
