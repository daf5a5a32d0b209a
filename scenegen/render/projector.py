"""A projector as a Mitsuba emitter: a point light at the projector's centre whose radiant
intensity toward a point is the pattern's value at the pixel our camera model projects the point
to (:mod:`scenegen.spec.sensors.projector` states the radiometry).

Forward projection through the model is closed form (:func:`scenegen.geometry.camera.project_xyz`
in Dr.Jit arithmetic, distortion and skew included), so no inverse distortion is needed: the
emitter is sampled only by direction toward its centre (a delta position, like Mitsuba's
``point``), and the path integrator's shadow rays and interreflections do the rest. The pattern
is looked up nearest-pixel: projector pixel (c, r) covers OpenCV's [c - 0.5, c + 0.5) x
[r - 0.5, r + 0.5) (a DLP's square pixels). Parameters are opaque Dr.Jit values, so a new pose
or pattern reuses the compiled kernels. Light tracing (``sample_ray``) is not provided: the
pipeline renders with the ``path`` integrator, which never asks an emitter for rays.
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.geometry.camera import ALL_COEFFS, Camera, project_xyz
from scenegen.geometry.pose import Rigid3
from scenegen.render.arrays import to_jit
from scenegen.render.drjit_ops import DRJIT_OPS

EMITTER_PLUGIN = "scenegen_projector"


def projector_key(name: str) -> str:
    """The key of a spec projector's emitter in the scene dict."""
    return f"projector_{name}"


class ProjectorEmitter(mi.Emitter):
    """Mitsuba emitter implementing a projector exactly (module docstring); off (intensity 0)
    until :meth:`set_projector`."""

    def __init__(self, props):
        mi.Emitter.__init__(self, props)
        self.projector_name = props["projector_name"] if "projector_name" in props else ""
        self.m_flags = mi.EmitterFlags.DeltaPosition
        self.model = "pinhole"
        self.falloff_exponent = 0
        opaque = lambda x: dr.opaque(mi.Float, float(x))
        self.p = SimpleNamespace(**{k: opaque(v) for k, v in
                                    dict(fx=1, fy=1, cx=0, cy=0, skew=0, limit=math.inf, **dict.fromkeys(ALL_COEFFS, 0)).items()})
        self.R = [[opaque(float(i == j)) for j in range(3)] for i in range(3)]
        self.t = [opaque(0.0) for _ in range(3)]
        self.center = [0.0, 0.0, 0.0]
        self.size = (1, 1)
        self.width = dr.opaque(mi.Int32, 1)
        self.height = dr.opaque(mi.Int32, 1)
        self.pattern = [mi.Float(0.0) for _ in range(3)]

    def set_projector(self, camera: Camera, projector_from_world: Rigid3, relative_rgb: np.ndarray,
                      intensity_w_sr, falloff_exponent: int) -> None:
        """Show ``relative_rgb`` (H, W, 3) (the emitted fraction of ``intensity_w_sr`` (3,) W/sr per
        pixel, after the radiometry's response) from ``camera`` at ``projector_from_world``."""
        H, W = camera.height, camera.width
        rel = np.asarray(relative_rgb, np.float64)
        if rel.shape != (H, W, 3):
            raise ValueError(f"pattern is {rel.shape}, expected ({H}, {W}, 3) for the projector {self.projector_name!r}")
        opaque = lambda x: dr.opaque(mi.Float, float(x))
        p = camera.params()
        self.p = SimpleNamespace(**{k: opaque(getattr(p, k)) for k in ("fx", "fy", "cx", "cy", "skew", "limit") + ALL_COEFFS})
        self.model = camera.model
        self.falloff_exponent = int(falloff_exponent)
        self.R = [[opaque(projector_from_world.R[i, j]) for j in range(3)] for i in range(3)]
        self.t = [opaque(x) for x in projector_from_world.t]
        self.center = [float(x) for x in projector_from_world.inverse().t]
        self.size = (W, H)
        self.width, self.height = dr.opaque(mi.Int32, W), dr.opaque(mi.Int32, H)
        scale = np.asarray(intensity_w_sr, np.float64).reshape(3)
        self.pattern = [to_jit(mi.Float, rel[..., c] * scale[c], np.float32) for c in range(3)]

    def off(self) -> None:
        """Emit nothing (a view its rig's projector does not light)."""
        self.width, self.height = dr.opaque(mi.Int32, 1), dr.opaque(mi.Int32, 1)
        self.pattern = [mi.Float(0.0) for _ in range(3)]

    def intensity_toward(self, p_world, active=True):
        """(radiant intensity W/sr per channel toward world points, the points' OpenCV pixel u, v
        in the projector): zero outside its image and where its model does not project (behind a
        perspective projector, beyond its fold), as :func:`project_xyz` says."""
        R, t = self.R, self.t
        X = R[0][0] * p_world.x + R[0][1] * p_world.y + R[0][2] * p_world.z + t[0]
        Y = R[1][0] * p_world.x + R[1][1] * p_world.y + R[1][2] * p_world.z + t[1]
        Z = R[2][0] * p_world.x + R[2][1] * p_world.y + R[2][2] * p_world.z + t[2]
        u, v, valid = project_xyz(X, Y, Z, self.p, self.model, DRJIT_OPS)
        col = mi.Int32(dr.floor(u + 0.5))
        row = mi.Int32(dr.floor(v + 0.5))
        inside = active & valid & (col >= 0) & (row >= 0) & (col < self.width) & (row < self.height)
        index = mi.UInt32(dr.select(inside, row * self.width + col, 0))
        value = mi.Color3f(*[dr.gather(mi.Float, ch, index, inside) for ch in self.pattern])
        if self.falloff_exponent:
            cos_alpha = Z / dr.sqrt(X * X + Y * Y + Z * Z)
            value = value * dr.power(cos_alpha, self.falloff_exponent)
        return dr.select(inside, value, 0.0), u, v

    def sample_direction(self, it, sample, active=True):
        ds = dr.zeros(mi.DirectionSample3f)
        ds.p = mi.Point3f(*self.center)
        ds.n = mi.Normal3f(0.0)
        ds.pdf = mi.Float(1.0)
        ds.time = it.time
        ds.delta = mi.Bool(True)
        d = ds.p - it.p
        ds.dist = dr.norm(d)
        inv = dr.rcp(ds.dist)
        ds.d = d * inv
        value, _, _ = self.intensity_toward(it.p, active)
        return ds, dr.select(active, value * dr.square(inv), 0.0)

    def pdf_direction(self, it, ds, active=True):
        return mi.Float(0.0)  # a delta position: no direction density

    def eval(self, si, active=True):
        return mi.Color3f(0.0)  # rays never hit a point light

    def sample_wavelengths(self, si, sample, active=True):
        return mi.Color0f(), mi.Color3f(1.0)

    def bbox(self):
        return mi.ScalarBoundingBox3f(mi.ScalarPoint3f(*self.center))

    def to_string(self):
        return f"ProjectorEmitter[{self.projector_name}]"


def register() -> None:
    """Register the emitter plugin with the current Mitsuba variant."""
    mi.register_emitter(EMITTER_PLUGIN, lambda props: ProjectorEmitter(props))


def projector_entry(name: str) -> dict:
    return {"type": EMITTER_PLUGIN, "projector_name": name}


def show(device, name: str, projector_from_world: Rigid3, pattern_values: np.ndarray) -> None:
    """Switch every projector of a device scene off but ``name``, which shows ``pattern_values``
    (H, W) or (H, W, 3) in [0, 1] from ``projector_from_world`` with its spec's radiometry."""
    spec = device.description.projectors[name]
    rel = spec.relative_output(pattern_values)
    rel = np.broadcast_to(rel[..., None], rel.shape + (3,)) if rel.ndim == 2 else rel
    for other, emitter in device.projectors.items():
        if other != name:
            emitter.off()
    device.projectors[name].set_projector(spec.to_camera(), projector_from_world, rel, spec.intensity_w_sr,
                                          spec.falloff_exponent)


def all_off(device) -> None:
    """Switch every projector of a device scene off."""
    for emitter in device.projectors.values():
        emitter.off()
