"""Albedo truth: the diffuse reflectance the renderer used at the surface each pixel centre's
ray hits (linear RGB, per channel), read from Mitsuba's own BSDF
(``BSDF.eval_diffuse_reflectance``: a ``diffuse`` BSDF's ``reflectance`` texture at the hit's
uv, a ``plastic``'s ``diffuse_reflectance``, a ``principled``'s base colour weighted as Mitsuba
weights it), so a texture, a mesh's own material or a variant's colour is the one the image shows.

The rays are the truth pass's (:mod:`scenegen.render.truth`: the same float64 pixel-centre
directions rounded once to float32, the same origin), through alpha-mask holes where the scene
has masks. Misses are NaN. For a global-shutter view of a static scene; the pipeline refuses
the rest.
"""
from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3
from scenegen.render.alpha import opaque_intersect
from scenegen.render.truth import camera_rays


def albedo_pass(scene, camera: Camera, cam_from_world: Rigid3, alpha_masked: bool = False) -> np.ndarray:
    """(H, W, 3) float32 diffuse albedo per pixel centre (NaN where the ray hits nothing)."""
    if mi.variant().startswith("scalar"):
        raise NotImplementedError("albedo truth needs a vectorised Mitsuba variant (llvm_ad_rgb / cuda_ad_rgb)")
    H, W = camera.height, camera.width
    world_from_cam = cam_from_world.inverse()
    d_world = camera_rays(camera) @ world_from_cam.R.T  # (H*W, 3) float64, as the truth pass rotates them
    origin = mi.Point3f(*[float(c) for c in world_from_cam.t])
    ray = mi.Ray3f(origin, mi.Vector3f(*[mi.Float(np.ascontiguousarray(d_world[:, i], np.float32))
                                         for i in range(3)]))
    if alpha_masked:
        si, _ = opaque_intersect(scene, ray, mi.RayFlags.All, coherent=True)
    else:
        si = scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=True)
    valid = si.is_valid()
    rho = si.bsdf(ray).eval_diffuse_reflectance(si, valid)
    out = [dr.select(valid, c, dr.nan) for c in (rho[0], rho[1], rho[2])]
    dr.eval(*out)
    return np.stack([c.numpy() for c in out], axis=-1).reshape(H, W, 3).astype(np.float32, copy=False)
