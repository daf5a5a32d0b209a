"""Our camera model as a Mitsuba sensor: the renderer's rays come from scenegen.camera's arithmetic.

The sensor generates each ray by unprojecting the film sample through :func:`unproject_uv`
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

from scenegen.camera import OPENCV_COEFFS, Camera, unproject_uv
from scenegen.conventions import opencv_pixel_from_film
from scenegen.pose import Rigid3

SENSOR_PLUGIN = "scenegen_camera"


class ScenegenSensor(mi.Sensor):
    """Mitsuba sensor implementing a :class:`scenegen.camera.Camera` exactly.

    Properties: ``film`` and ``sampler`` as for any sensor. The camera is set with
    :meth:`set_camera` (the builder does it right after loading).
    """

    def __init__(self, props):
        mi.Sensor.__init__(self, props)
        # Mitsuba gives Python sensors of one scene the same id(): keep our own name
        self.camera_name = props["camera_name"] if "camera_name" in props else ""
        self.model = "pinhole"
        self.iterations = 0
        self.p = None
        self.R_world_from_cam = None
        self.center_world = None

    def set_camera(self, camera: Camera, cam_from_world: Rigid3) -> None:
        """Use ``camera`` at pose ``cam_from_world``; the film must already have its size."""
        film_size = tuple(int(s) for s in self.film().size())
        if film_size != camera.size:
            raise ValueError(f"film is {film_size[0]}x{film_size[1]} but the camera is {camera.width}x{camera.height}")
        opaque = lambda x: dr.opaque(mi.Float, float(x))
        p = camera.params()
        fields = ("fx", "fy", "cx", "cy", "skew") + OPENCV_COEFFS
        self.p = SimpleNamespace(**{k: opaque(getattr(p, k)) for k in fields})
        self.model = camera.model
        self.iterations = camera.undistort_iterations
        world_from_cam = cam_from_world.inverse()
        self.R_world_from_cam = [[opaque(world_from_cam.R[i, j]) for j in range(3)] for i in range(3)]
        self.center_world = [opaque(c) for c in world_from_cam.t]

    def camera_rays(self, sample2):
        """Unit ray directions in the world for film samples (Point2f in [0, 1]^2 of the crop)."""
        size = self.film().crop_size()
        offset = self.film().crop_offset()
        u, v = opencv_pixel_from_film(sample2, size, offset)
        dx, dy, dz = unproject_uv(u, v, self.p, self.model, self.iterations)
        R = self.R_world_from_cam
        d = mi.Vector3f(R[0][0] * dx + R[0][1] * dy + R[0][2] * dz,
                        R[1][0] * dx + R[1][1] * dy + R[1][2] * dz,
                        R[2][0] * dx + R[2][1] * dy + R[2][2] * dz)
        return d

    def sample_ray(self, time, sample1, sample2, sample3, active=True):
        wavelengths, wav_weight = self.sample_wavelengths(dr.zeros(mi.SurfaceInteraction3f), sample1, active)
        d = self.camera_rays(sample2)
        o = mi.Point3f(*self.center_world)
        return mi.Ray3f(o, d, time, wavelengths), wav_weight

    def sample_ray_differential(self, time, sample1, sample2, sample3, active=True):
        ray, weight = self.sample_ray(time, sample1, sample2, sample3, active)
        return mi.RayDifferential3f(ray), weight

    def to_string(self):
        return f"ScenegenSensor[model={self.model}]"


_registered = False


def register() -> None:
    """Register the sensor plugin with the current Mitsuba variant (idempotent per variant)."""
    global _registered
    mi.register_sensor(SENSOR_PLUGIN, lambda props: ScenegenSensor(props))
    _registered = True


def sensor_dict(camera: Camera, *, spp: int, sampler: str = "ldsampler", seed: int = 0,
                pixel_format: str = "rgb", name: str = "") -> dict:
    """Mitsuba dict for our sensor with a float32 box-filtered film of the camera's size.

    The box filter keeps renders bitwise deterministic and pixel values unblurred across pixels.
    """
    return {
        "type": SENSOR_PLUGIN,
        "camera_name": name,
        "film": {"type": "hdrfilm", "width": camera.width, "height": camera.height,
                 "rfilter": {"type": "box"}, "pixel_format": pixel_format, "component_format": "float32"},
        "sampler": {"type": sampler, "sample_count": int(spp), "seed": int(seed)},
    }


def as_numpy_image(bitmap_tensor) -> np.ndarray:
    return np.array(bitmap_tensor, dtype=np.float32)
