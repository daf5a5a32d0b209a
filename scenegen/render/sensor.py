"""Our camera model as a Mitsuba sensor: the renderer's rays come from scenegen.geometry.camera's arithmetic.

The sensor generates each ray by unprojecting the film sample through
:func:`scenegen.geometry.camera.unproject_uv` with Dr.Jit's operations
(distortion, skew and fx != fy included; no post-warp resampling) and rotating it into the world
with the OpenCV ``world_from_cam`` pose. Mitsuba's own camera frame (x left, y up) is never used.
Camera parameters and the pose are opaque Dr.Jit scalars, so a new camera of the same model
reuses the compiled kernels; :meth:`ScenegenSensor.set_camera` swaps them between renders.
"""
from __future__ import annotations

from types import SimpleNamespace

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.geometry.camera import ALL_COEFFS, Camera, unproject_uv
from scenegen.geometry.conventions import opencv_pixel_from_film
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import rotvec_from_matrix
from scenegen.render.arrays import to_jit
from scenegen.render.drjit_ops import DRJIT_OPS
from scenegen.spec.model.render import effective_spp

SENSOR_PLUGIN = "scenegen_camera"
#: Nodes of a camera path's table over one frame's exposure and readout (optics.PathMotion):
#: the sensor interpolates between them; 129 nodes over 20 ms put them 0.16 ms apart, where a
#: path accelerating at 10 m/s^2 leaves its chord by 3e-8 m.
PATH_NODES = 129


class ScenegenSensor(mi.Sensor):
    """Mitsuba sensor implementing a :class:`scenegen.geometry.camera.Camera` exactly.

    Properties: ``film`` and ``sampler`` as for any sensor. The camera is set with
    :meth:`set_camera` (the builder does it right after loading).
    """

    def __init__(self, props):
        mi.Sensor.__init__(self, props)
        # Mitsuba gives Python sensors of one scene the same id(): keep our own name
        self.camera_name = props["camera_name"] if "camera_name" in props else ""
        self.m_needs_sample_3 = True  # the aperture sample of the thin lens
        self.model = "pinhole"
        self.iterations = 0
        self.p = None
        self.R_world_from_cam = None
        self.center_world = None
        self.height = 1
        self.lens = None  # (aperture radius m, focus distance m), opaque
        self.time_model = None  # see set_camera
        self.fold_mask = False
        self.time_bin = None  # (lo, hi) seconds: see set_camera

    def set_camera(self, camera: Camera, cam_from_world: Rigid3, optics=None, motion=None,
                   time_window=(0.0, 1.0), time_bin=None) -> None:
        """Use ``camera`` at pose ``cam_from_world`` (the mid-exposure pose).

        ``optics`` (:class:`scenegen.geometry.optics.Optics`) adds a thin lens and a shutter; ``motion``
        (:class:`scenegen.geometry.optics.Motion`, camera-frame velocities) moves the camera over the
        exposure. ``time_window`` is the part of the exposure this render covers (sub-frames).
        ``time_bin`` (lo, hi), seconds from mid-exposure: only samples whose time (their row's
        time plus their place in the exposure) falls in [lo, hi) count; the others get weight 0
        and a ray that hits nothing (rolling-shutter sub-frames, :func:`scenegen.render.frames.render_view`).
        The film must already have the camera's size.
        """
        film_size = tuple(int(s) for s in self.film().size())
        if film_size != camera.size:
            raise ValueError(f"film is {film_size[0]}x{film_size[1]} but the camera is {camera.width}x{camera.height}")
        opaque = lambda x: dr.opaque(mi.Float, float(x))
        p = camera.params()
        fields = ("fx", "fy", "cx", "cy", "skew") + ALL_COEFFS
        self.p = SimpleNamespace(**{k: opaque(getattr(p, k)) for k in fields})
        self.fold_mask = camera.mask_beyond_fold  # pixels beyond the fold: no ray (weight 0)
        if self.fold_mask:
            self.p.mask_beyond_fold, self.p.limit = True, opaque(p.limit)
        self.model = camera.model
        self.iterations = camera.undistort_iterations
        self.height = camera.height
        world_from_cam = cam_from_world.inverse()
        self.R_world_from_cam = [[opaque(world_from_cam.R[i, j]) for j in range(3)] for i in range(3)]
        self.center_world = [opaque(c) for c in world_from_cam.t]
        lens = getattr(optics, "lens", None)
        self.lens = None if lens is None else (opaque(lens.aperture_radius_m(camera)), opaque(lens.focus_distance_m))
        shutter = getattr(optics, "shutter", None)
        exposure = 0.0 if shutter is None else shutter.exposure_s
        readout = 0.0 if shutter is None else shutter.rolling_readout_s
        moving = motion is not None and not motion.is_static and (exposure > 0 or readout > 0)
        if moving and hasattr(motion, "trajectory"):  # optics.PathMotion: the curve, as a table
            half = 0.5 * (exposure + readout)
            taus = np.linspace(-half, half, PATH_NODES)
            deltas = [motion.delta(float(t)) for t in taus]
            rv = np.stack([rotvec_from_matrix(dl.R) for dl in deltas])
            tv = np.stack([dl.t for dl in deltas])
            table = lambda a: to_jit(mi.Float, a, np.float32)
            self.time_model = SimpleNamespace(
                t0=opaque(time_window[0]), t1=opaque(time_window[1]), exposure=opaque(exposure),
                readout=opaque(readout), half=opaque(half), inv_step=opaque((PATH_NODES - 1) / (2 * half)),
                rotvec=[table(rv[:, i]) for i in range(3)], shift=[table(tv[:, i]) for i in range(3)])
        elif moving:
            w = motion.angular_velocity_rad_s
            speed = float(np.linalg.norm(w))
            axis = w / speed if speed > 0 else np.zeros(3)
            self.time_model = SimpleNamespace(
                t0=opaque(time_window[0]), t1=opaque(time_window[1]), exposure=opaque(exposure),
                readout=opaque(readout), speed=opaque(speed), rotating=speed > 0,
                axis=[opaque(a) for a in axis], v=[opaque(c) for c in motion.linear_velocity_mps])
        elif time_bin is not None:  # a still camera: only the samples' times
            self.time_model = SimpleNamespace(t0=opaque(time_window[0]), t1=opaque(time_window[1]),
                                              exposure=opaque(exposure), readout=opaque(readout), still=True)
        else:
            self.time_model = None
        self.time_bin = None if time_bin is None else tuple(opaque(x) for x in time_bin)

    def camera_frame_rays(self, sample2, sample3, time):
        """(origins, unit directions, the sample's time in seconds from mid-exposure or None) in
        the OpenCV camera frame at mid-exposure pose.

        The chief ray comes from our camera model; a thin lens moves the origin over the aperture
        and aims at the chief ray's point on the focus plane (depth z = focus distance); camera
        motion turns and shifts the ray by the pose change at the sample's time.
        """
        size = self.film().crop_size()
        offset = self.film().crop_offset()
        u, v = opencv_pixel_from_film(sample2, size, offset)
        dx, dy, dz = unproject_uv(u, v, self.p, self.model, self.iterations, DRJIT_OPS)
        o = mi.Vector3f(0.0)
        d = mi.Vector3f(dx, dy, dz)
        if self.lens is not None:
            radius, focus = self.lens
            a = mi.warp.square_to_uniform_disk_concentric(sample3) * radius
            o = mi.Vector3f(a.x, a.y, 0.0)
            d = dr.normalize(d * (focus / dz) - o)
        tm = self.time_model
        if tm is None:
            return o, d, None
        # seconds from mid-exposure: position in the (sub-frame) window, plus the row's offset
        tau = (tm.t0 + time * (tm.t1 - tm.t0) - 0.5) * tm.exposure
        tau = tau + tm.readout * (v / max(self.height - 1, 1) - 0.5)  # = optics.Shutter.row_time_s(v)
        if hasattr(tm, "rotvec"):
            return (*self._along_path(tm, tau, o, d), tau)
        if hasattr(tm, "still"):
            return o, d, tau
        if tm.rotating:  # Rodrigues: world_from_cam(tau) = world_from_cam @ [exp(w tau) | v tau]
            k = mi.Vector3f(*tm.axis)
            ang = tm.speed * tau
            c, s = dr.cos(ang), dr.sin(ang)
            rot = lambda x: x * c + dr.cross(k, x) * s + k * dr.dot(k, x) * (1.0 - c)
            o, d = rot(o), rot(d)
        o = o + mi.Vector3f(*tm.v) * tau
        return o, d, tau

    @staticmethod
    def _along_path(tm, tau, o, d):
        """Turn and shift camera-frame rays by the path's displacement at ``tau``: rotation vector
        and shift interpolated linearly between the table's PATH_NODES nodes over the window."""
        f = dr.clip((tau + tm.half) * tm.inv_step, 0.0, PATH_NODES - 1.0001)
        k = mi.UInt32(f)
        a = f - mi.Float(k)
        lerp = lambda tab: dr.gather(mi.Float, tab, k) * (1.0 - a) + dr.gather(mi.Float, tab, k + 1) * a
        r = mi.Vector3f(*[lerp(t) for t in tm.rotvec])
        ang = dr.norm(r)
        axis = r / dr.maximum(ang, 1e-30)
        c, s = dr.cos(ang), dr.sin(ang)
        rot = lambda x: x * c + dr.cross(axis, x) * s + axis * dr.dot(axis, x) * (1.0 - c)
        return rot(o) + mi.Vector3f(*[lerp(t) for t in tm.shift]), rot(d)

    def sample_ray(self, time, sample1, sample2, sample3, active=True):
        wavelengths, wav_weight = self.sample_wavelengths(dr.zeros(mi.SurfaceInteraction3f), sample1, active)
        o, d, tau = self.camera_frame_rays(sample2, sample3, time)
        R, C = self.R_world_from_cam, self.center_world
        rot = lambda x: mi.Vector3f(R[0][0] * x.x + R[0][1] * x.y + R[0][2] * x.z,
                                    R[1][0] * x.x + R[1][1] * x.y + R[1][2] * x.z,
                                    R[2][0] * x.x + R[2][1] * x.y + R[2][2] * x.z)
        if self.fold_mask:  # no ray beyond the fold radius: a harmless direction, weight 0
            ok = dr.isfinite(d.x) & dr.isfinite(d.y) & dr.isfinite(d.z)
            d = dr.select(ok, d, mi.Vector3f(0.0, 0.0, 1.0))
            o = dr.select(ok, o, mi.Vector3f(0.0))
            wav_weight = dr.select(ok, wav_weight, 0.0)
        origin = mi.Point3f(rot(o) + mi.Vector3f(*C))
        ray = mi.Ray3f(origin, rot(d), time, wavelengths)
        if self.time_bin is not None:  # a sample outside this sub-frame's time: no weight, no hit
            lo, hi = self.time_bin
            inside = (tau >= lo) & (tau < hi)
            wav_weight = dr.select(inside, wav_weight, 0.0)
            ray.maxt = dr.select(inside, ray.maxt, 0.0)
        return ray, wav_weight

    def sample_ray_differential(self, time, sample1, sample2, sample3, active=True):
        ray, weight = self.sample_ray(time, sample1, sample2, sample3, active)
        return mi.RayDifferential3f(ray), weight

    def to_string(self):
        return f"ScenegenSensor[model={self.model}]"


def register() -> None:
    """Register the sensor plugin with the current Mitsuba variant (registering again replaces it)."""
    mi.register_sensor(SENSOR_PLUGIN, lambda props: ScenegenSensor(props))


def sensor_dict(camera: Camera, *, spp: int, sampler: str = "ldsampler", seed: int = 0,
                pixel_format: str = "rgb", name: str = "", timed: bool = False) -> dict:
    """Mitsuba dict for our sensor with a float32 box-filtered film of the camera's size.

    The box filter keeps renders bitwise deterministic and pixel values unblurred across pixels.
    """
    return {
        "type": SENSOR_PLUGIN,
        "camera_name": name,
        # a shutter interval makes Mitsuba draw a time in [0, 1) per sample (motion blur)
        **({"shutter_open": 0.0, "shutter_close": 1.0} if timed else {}),
        "film": {"type": "hdrfilm", "width": camera.width, "height": camera.height,
                 "rfilter": {"type": "box"}, "pixel_format": pixel_format, "component_format": "float32"},
        # the count the sampler takes (it rounds up; asking for that count renders the same samples
        # and keeps Mitsuba from logging a WARN line for the rounding)
        "sampler": {"type": sampler, "sample_count": effective_spp(sampler, int(spp)), "seed": int(seed)},
    }


