"""Alpha masks in the truth rays: the first surface a ray hits that is opaque where it is hit.

Mitsuba's ``ray_intersect`` ignores a ``mask`` BSDF (it finds the triangle, not whether the texel
is a hole); the path tracer then passes through holes with probability 1 - opacity. So that the
truth agrees with the image, truth and visibility rays of a scene with alpha masks ask the hit
surface its opacity (``eval_null_transmission`` = 1 - opacity, 0 for every BSDF but ``mask``) and,
where the opacity is below :data:`OPAQUE_AT`, continue the ray from just beyond the hit, up to
:data:`ALPHA_LAYERS` holes in a row. A binary mask (the default ``alpha_cutoff``, and glTF
``MASK``) is 0 or 1 per texel, sampled nearest-texel: truth and image agree texel for texel. With
continuous opacity (``alpha_blend``, glTF ``BLEND``, MTL ``d`` < 1) the image blends; the truth
takes the surface where it is at least half opaque.

Only scenes with a mask take this path (:attr:`scenegen.render.scene.LoadedScene.alpha_masked`);
others cast exactly the rays they always did. The distance of a ray continued through holes is
the sum of its segments (each restart offset by ~1e-6 x the coordinates' magnitude), so it is
float32-accurate rather than Mitsuba's single ``si.t``.
"""
from __future__ import annotations

import drjit as dr
import mitsuba as mi

from scenegen.render.materials import OPAQUE_AT

#: Holes in a row a truth ray passes through before it takes the next surface as hit.
ALPHA_LAYERS = 8
#: Restart offset beyond a hole, relative to (1 + the hit point's largest |coordinate|).
RESTART_REL = 2.0**-20


def opaque_intersect(scene, ray, ray_flags, coherent: bool = True, layers: int = ALPHA_LAYERS):
    """(SurfaceInteraction3f of the first opaque hit, its distance along ``ray`` (mi.Float;
    inf on misses))."""
    flags = ray_flags | mi.RayFlags.UV
    si = scene.ray_intersect(ray, ray_flags=flags, coherent=coherent)
    t = dr.select(si.is_valid(), si.t, dr.inf)
    d = mi.Vector3f(ray.d)
    for _ in range(layers):
        valid = si.is_valid()
        trans = si.bsdf().eval_null_transmission(si, valid)
        hole = valid & (trans[0] > 1.0 - OPAQUE_AT)
        eps = (1.0 + dr.max(dr.abs(si.p))) * RESTART_REL
        nxt = scene.ray_intersect(mi.Ray3f(si.p + d * eps, d), ray_flags=flags, coherent=coherent,
                                  active=hole)
        t = dr.select(hole, dr.select(nxt.is_valid(), t + eps + nxt.t, dr.inf), t)
        si = dr.select(hole, nxt, si)
    return si, t
