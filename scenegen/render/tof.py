"""Path-length-resolved rendering for an AMCW time-of-flight camera: a wavefront path tracer
in Dr.Jit that carries each path's optical length and sums its contribution as a phasor per
modulation frequency (the phase convention: :mod:`scenegen.geometry.tof`).

The light is the ToF camera's own emitter only: an isotropic point source of unit radiant
intensity at the camera's optical centre (co-located illumination). The scene's lights are not
part of the modulated signal (an IR band-pass filter; their DC is the spec's ``ambient``, a
model). Each camera ray meets a surface, takes the emitter's light by next-event estimation at
every vertex (a shadow ray to the centre; the path's length is the camera-side length plus the
distance back to the emitter), and continues by BSDF sampling for ``max_bounces`` vertices in
all. So the indirect light Mitsuba's materials scatter gives the multipath interference, and a
pixel's sub-pixel rays that meet surfaces at different ranges give mixed returns (flying pixels)
through the same sum: both are physics of the rendered light transport, not added models.

Per pixel, the outputs are Monte Carlo means over the pixel's rays (units of the rendered
radiance for a unit-intensity source: a white Lambertian surface facing the camera at 1 m gives
``dc = 1 / pi``): ``dc`` (S0), ``cos_<k>`` / ``sin_<k>`` (Re / Im of the phasor at frequency k),
the same of the direct (one-vertex) light alone (``direct_*``), and the fraction of the pixel's
rays that meet a surface (``hit_fraction``).
The colour of a material is reduced to the mean of its R, G, B transport (the reflectance at the
emitter's wavelength is a model). Delta (mirror, glass) vertices cannot reach a point emitter by
next-event estimation, so paths through them carry no ToF signal: a stated limitation.

Sub-pixel positions: ``centre`` puts every ray at the pixel centre (the exact-range checks);
otherwise each ray is uniform in its pixel square, drawn from ``seed`` (numpy), and the bounce
samples come from Mitsuba's independent sampler seeded with ``seed``: same inputs, same bits.
"""
from __future__ import annotations

import math

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.tof import SPEED_OF_LIGHT_M_S
from scenegen.render.arrays import to_jit

#: Rays traced in one wavefront at most (memory: about 0.5 KB per ray over a bounce).
WAVEFRONT_RAYS = 1 << 21


def subpixel_positions(pixels: np.ndarray, spp: int, rng, centre: bool) -> np.ndarray:
    """(P*spp, 2) float64 OpenCV pixel positions of the (P, 2) pixel centres, pixel-major (a
    pixel's rays together): the centres themselves, or uniform in each pixel's square."""
    c = np.repeat(pixels, spp, axis=0)
    return c if centre else c + rng.uniform(-0.5, 0.5, size=c.shape)


def tof_pass(scene, camera: Camera, cam_from_world: Rigid3, freqs_hz, *, spp: int, seed: int,
             max_bounces: int, centre: bool = False) -> dict[str, np.ndarray]:
    """The per-pixel path sums of the module docstring, each (H, W) float64. Pixels are traced in
    blocks of at most :data:`WAVEFRONT_RAYS` rays, block b's positions and bounces seeded by
    (seed, b), so memory stays bounded whatever the image size."""
    H, W, spp = camera.height, camera.width, int(spp)
    world_from_cam = cam_from_world.inverse()
    centre_world = np.asarray(world_from_cam.t, np.float64)
    pixels = pixel_centers(W, H).reshape(-1, 2)
    block = max(1, WAVEFRONT_RAYS // spp)
    parts = []
    for b, start in enumerate(range(0, len(pixels), block)):
        uv = subpixel_positions(pixels[start:start + block], spp, np.random.default_rng([int(seed), b]), centre)
        d_world = camera.unproject_unit(uv) @ world_from_cam.R.T  # (N, 3) float64, unit
        sums = _trace(scene, centre_world, d_world, tuple(float(f) for f in freqs_hz), int(max_bounces),
                      (int(seed) * 7919 + b) % 2 ** 32)
        parts.append({k: v.reshape(-1, spp).mean(axis=-1) for k, v in sums.items()})
    return {k: np.concatenate([p[k] for p in parts]).reshape(H, W) for k in parts[0]}


def _phasor_add(acc, key, contrib64, length_m, freqs):
    for k, f in enumerate(freqs):
        phase = length_m * (2.0 * math.pi * f / SPEED_OF_LIGHT_M_S)
        acc[f"{key}cos_{k}"] += contrib64 * dr.cos(phase)
        acc[f"{key}sin_{k}"] += contrib64 * dr.sin(phase)


def _trace(scene, centre_world, d_world, freqs, max_bounces: int, seed: int) -> dict[str, np.ndarray]:
    n = len(d_world)
    c = mi.Point3f(*[float(x) for x in centre_world])
    o = mi.Point3f(*[dr.full(mi.Float, float(x), n) for x in centre_world])
    d = mi.Vector3f(*[to_jit(mi.Float, d_world[:, i], np.float32) for i in range(3)])
    ray = mi.Ray3f(o, d)
    sampler = mi.load_dict({"type": "independent", "sample_count": 1})
    sampler.seed(seed, n)
    ctx = mi.BSDFContext()
    zero = lambda: dr.zeros(mi.Float64, n)
    acc = {"dc": zero(), "direct_dc": zero()}
    for pre in ("", "direct_"):
        for k in range(len(freqs)):
            acc[f"{pre}cos_{k}"], acc[f"{pre}sin_{k}"] = zero(), zero()
    throughput = mi.Spectrum(1.0)
    length = dr.zeros(mi.Float64, n)  # camera-side optical length so far, metres
    active = dr.full(mi.Bool, True, n)
    hit = None
    for bounce in range(max_bounces):
        si = scene.ray_intersect(ray, active)
        active &= si.is_valid()
        length += mi.Float64(dr.select(active, si.t, 0.0))
        if bounce == 0:
            hit = mi.Float64(dr.select(active, 1.0, 0.0))
        to_c = c - si.p
        dist = dr.norm(to_c)
        wo = to_c / dist
        bsdf = si.bsdf(ray)
        shadow = si.spawn_ray_to(c)
        seen = active & ~scene.ray_test(shadow, active)
        f = bsdf.eval(ctx, si, si.to_local(wo), seen)
        contrib = mi.Float64(dr.select(seen, dr.mean(throughput * f) / dr.square(dist), 0.0))
        total = length + mi.Float64(dist)
        acc["dc"] += contrib
        _phasor_add(acc, "", contrib, total, freqs)
        if bounce == 0:
            acc["direct_dc"] += contrib
            _phasor_add(acc, "direct_", contrib, total, freqs)
        if bounce + 1 < max_bounces:
            bs, weight = bsdf.sample(ctx, si, sampler.next_1d(active), sampler.next_2d(active), active)
            throughput *= weight
            active &= (bs.pdf > 0) & (dr.max(throughput) > 0)
            ray = si.spawn_ray(si.to_world(bs.wo))
        dr.eval(throughput, length, active, ray, *acc.values())
    outs = dict(acc, hit_fraction=hit)
    dr.eval(*outs.values())
    return {k: np.array(v, dtype=np.float64) for k, v in outs.items()}
