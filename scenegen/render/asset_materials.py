"""A mesh file's own materials (:class:`scenegen.assets.mesh_materials.AssetMaterial`) -> Mitsuba
BSDF dicts, and the wrappers that every material may carry (normal map, bump map, alpha mask).

Mappings (documented in docs/scene_spec.md, "Meshes with their own materials"):

* MTL without ``Ks`` (or Ks = 0): ``diffuse`` with Kd (x map_Kd). With Ks: ``roughplastic``
  (Beckmann) with diffuse Kd, specular Ks and alpha = sqrt(2 / (Ns + 2)) (the Blinn-Phong
  exponent's Beckmann equivalent, Walter et al. 2007), IOR 1.5.
* glTF: Mitsuba's ``principled`` with base_color, metallic, roughness (both perceptual, as in
  glTF) and specular 0.5 (F0 = 0.04, glTF's dielectric); ``doubleSided`` -> ``twosided``.
* vertex colours: ``diffuse`` whose reflectance is the mesh attribute ``vertex_color``.
* emission: an ``area`` emitter on the part (radiance = factor x texture).
* alpha: ``mask`` with the opacity texture; ``mask`` mode thresholds it at the cutoff into a
  0/1 texture sampled nearest-texel (what the truth pass tests, see
  :mod:`scenegen.render.alpha`); ``blend`` keeps it continuous (bilinear).
"""
from __future__ import annotations

import numpy as np

from scenegen.render.materials import bitmap, rgb, value_bitmap, with_alpha, with_bump_map, with_normal_map


def _scaled(texture, factor) -> np.ndarray:
    return np.asarray(texture, np.float32) * np.asarray(factor, np.float32)[None, None, :]


def _base(am) -> dict:
    if am.vertex_colors is not None:
        return {"type": "mesh_attribute", "name": "vertex_color"}
    if am.base_texture is not None:
        return bitmap(np.clip(_scaled(am.base_texture, am.base_color), 0.0, 1.0))
    return rgb(am.base_color)


def _principled(am) -> dict:
    d = {"type": "principled", "base_color": _base(am), "specular": 0.5}
    if am.metallic_roughness_texture is not None:
        mr = np.asarray(am.metallic_roughness_texture, np.float32)
        d["metallic"] = value_bitmap(mr[..., 2] * am.metallic)
        d["roughness"] = value_bitmap(mr[..., 1] * am.roughness)
    else:
        d["metallic"], d["roughness"] = float(am.metallic), float(am.roughness)
    return d


def asset_bsdf(am) -> dict:
    """The Mitsuba BSDF dict of a mesh part's own material."""
    if am.metallic is not None:
        bsdf = _principled(am)
    elif am.specular is not None:
        ns = 0.0 if am.shininess is None else max(float(am.shininess), 0.0)
        bsdf = {"type": "roughplastic", "distribution": "beckmann", "alpha": float(np.sqrt(2.0 / (ns + 2.0))),
                "diffuse_reflectance": _base(am), "specular_reflectance": rgb(am.specular), "int_ior": 1.5}
    else:
        bsdf = {"type": "diffuse", "reflectance": _base(am)}
    bsdf = with_bump_map(bsdf, am.bump_texture, am.bump_scale)
    bsdf = with_normal_map(bsdf, am.normal_texture)
    if am.double_sided:
        bsdf = {"type": "twosided", "bsdf": bsdf}
    return with_alpha(bsdf, am.opacity, am.opacity_texture, am.alpha_mode, am.alpha_cutoff)


def asset_emitter(am) -> dict | None:
    """An ``area`` emitter for an emissive part, else None."""
    if am.emissive_texture is None and max(am.emissive) <= 0:
        return None
    if am.emissive_texture is not None:
        radiance = bitmap(_scaled(am.emissive_texture, am.emissive))
    else:
        radiance = rgb(am.emissive)
    return {"type": "area", "radiance": radiance}
