"""The calibrated lights of a view (``truth: {lights: true}``): every spec light that is on in
the view, stated in the view's camera frame (OpenCV axes), as photometric stereo's calibration
gives them (DiLiGenT's light_directions.txt / light_intensities.txt, in our axes; the conversion
is :data:`scenegen.geometry.conventions.DILIGENT_FROM_OPENCV_CAM`).

Powers carry the view's ``lights:`` factor. A directional light's ``intensity`` is
irradiance / pi: the radiance a white Lambertian surface facing the light reflects, so a
Lambertian pixel is ``albedo * max(0, n . l) * intensity`` per channel (Mitsuba's ``diffuse``
BSDF is albedo / pi).
"""
from __future__ import annotations

import math

import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.spec import model as m

#: The document's format tag (docs/dataset_format.md, "Albedo and light truth").
LIGHTS_FORMAT = "scenegen.lights/1"
FRAME = "camera: OpenCV axes (+x right, +y down, +z forward), metres"


def _vec(R: np.ndarray, v) -> list[float]:
    return [float(x) for x in R @ np.asarray(v, np.float64)]


def _point(cam_from_world: Rigid3, p) -> list[float]:
    return [float(x) for x in cam_from_world.apply(np.asarray(p, np.float64)[None])[0]]


def _scaled(rgb, k: float) -> list[float]:
    return [float(k) * float(c) for c in rgb]


def light_record(light, factor: float, cam_from_world: Rigid3) -> dict:
    """One light as the view's camera sees it (see the module docstring)."""
    R = cam_from_world.R
    d: dict = {"name": light.name, "type": light.type, "factor": float(factor)}
    if isinstance(light, m.DirectionalLight):
        E = _scaled(light.irradiance, factor)
        d.update(direction_to_light_cam=_vec(R, light.unit_direction_to_light), irradiance_w_m2=E,
                 intensity=[e / math.pi for e in E])
    elif isinstance(light, m.PointLight):
        d.update(position_cam=_point(cam_from_world, light.position),
                 intensity_w_sr=_scaled(light.intensity, factor))
    elif isinstance(light, m.SpotLight):
        d.update(position_cam=_point(cam_from_world, light.position),
                 axis_cam=_vec(R, light.world_from_light.R[:, 2]),
                 intensity_w_sr=_scaled(light.intensity, factor), cutoff_deg=float(light.cutoff_deg),
                 beam_width_deg=float(light.beam_width_deg))
    elif isinstance(light, m.AreaLight):
        w = light.world_from_light
        d.update(center_cam=_point(cam_from_world, w.t), normal_cam=_vec(R, w.R[:, 2]),
                 size_m=[float(s) for s in light.size], radiance=_scaled(light.radiance, factor))
    elif isinstance(light, m.ConstantLight):
        d.update(radiance=_scaled(light.radiance, factor))
    else:  # an environment map: its image and orientation are in the spec (cameras.json)
        d.update(scale=float(light.scale) * float(factor))
    return d


def view_lights_document(spec: m.SceneSpec, view: m.View) -> dict:
    """The lights that are on in ``view`` (factor > 0), spec order, in its camera frame."""
    scales = view.light_scales if view.light_scales is not None else (1.0,) * len(spec.lights)
    return {"format": LIGHTS_FORMAT, "frame": FRAME, "view": view.name,
            "lights": [light_record(li, k, view.cam_from_world) for li, k in zip(spec.lights, scales) if k > 0]}
