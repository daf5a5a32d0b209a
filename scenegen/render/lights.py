"""Spec lights -> Mitsuba emitters, one translation function per spec kind, and the lighting
state of a loaded scene (each view's ``lights:`` factors).

Lighting is passed in with every render (:func:`scenegen.render.frames.render_view` calls
:func:`set_lighting` with the view's factors, None = every light at its spec power), so what a
render shows never depends on what an earlier render set.
"""
from __future__ import annotations

import math

import mitsuba as mi
import numpy as np

from scenegen.assets.envmap import check_envmap
from scenegen.render.materials import rgb
from scenegen.spec import model as m
from scenegen.spec.assets_check import located


def _area(light: m.AreaLight) -> dict:
    T = light.world_from_light.matrix @ np.diag([light.size[0] / 2, light.size[1] / 2, 1.0, 1.0])
    return {"type": "rectangle", "to_world": mi.ScalarTransform4f(T),
            "emitter": {"type": "area", "radiance": rgb(light.radiance)},
            "bsdf": {"type": "diffuse", "reflectance": rgb((0.0, 0.0, 0.0))}}


def _point(light: m.PointLight) -> dict:
    return {"type": "point", "position": [float(x) for x in light.position], "intensity": rgb(light.intensity)}


def _spot(light: m.SpotLight) -> dict:
    # Mitsuba's spot shines along its local +z: the light frame's +z points at the target
    return {"type": "spot", "to_world": mi.ScalarTransform4f(light.world_from_light.matrix),
            "intensity": rgb(light.intensity), "cutoff_angle": float(light.cutoff_deg),
            "beam_width": float(light.beam_width_deg)}


def _constant(light: m.ConstantLight) -> dict:
    return {"type": "constant", "radiance": rgb(light.radiance)}


def _envmap(light: m.EnvmapLight) -> dict:
    # Mitsuba's envmap has +y up; ours is +z: rotate +y onto +z, then turn about +z.
    T = mi.ScalarTransform4f().rotate([0, 0, 1], light.rotation_z_deg) @ mi.ScalarTransform4f().rotate([1, 0, 0], 90)
    with located(light, f"light {light.name!r}"):  # the size by its header before Mitsuba allocates it
        check_envmap(light.path)
    return {"type": "envmap", "filename": str(light.path), "scale": float(light.scale), "to_world": T}


def _directional(light: m.DirectionalLight) -> dict:
    # Mitsuba's `direction` is the one the light travels in: away from the light
    return {"type": "directional", "direction": [-float(x) for x in light.unit_direction_to_light],
            "irradiance": rgb(light.irradiance)}


LIGHTS = {m.AreaLight: _area, m.PointLight: _point, m.SpotLight: _spot, m.ConstantLight: _constant,
          m.EnvmapLight: _envmap, m.DirectionalLight: _directional}

#: Mitsuba 3.9 parameters (relative to the light's key in the scene dict) that carry a light's
#: power: scaling one scales the light's contribution linearly (same paths, same samples).
EMITTER_POWER_PARAM = {
    m.AreaLight: "emitter.radiance.value",  # the rectangle's area emitter, W/(m^2 sr)
    m.PointLight: "intensity.value",  # W/sr
    m.SpotLight: "intensity.value",  # on-axis W/sr
    m.ConstantLight: "radiance.value",  # W/(m^2 sr)
    m.EnvmapLight: "scale",  # factor on the image's radiance
    m.DirectionalLight: "irradiance.value",  # W/m^2
}
#: ... and its share of the light samples: Mitsuba picks the emitter of a light sample in
#: proportion to this weight (1 by default), not to power.
EMITTER_WEIGHT_PARAM = {t: ("emitter." if t is m.AreaLight else "") + "sampling_weight"
                        for t in EMITTER_POWER_PARAM}


def light_entry(light) -> dict:
    """The Mitsuba dict of a spec light."""
    try:
        translate = LIGHTS[type(light)]
    except KeyError:
        raise TypeError(f"unknown light {type(light).__name__}") from None
    return translate(light)


def light_key(index: int) -> str:
    """The key of spec light ``index`` in the scene dict."""
    return f"light_{index:04d}"


def loaded_emitters(scene, lights) -> list:
    """Per spec light, in spec order: (key of its power, loaded power value, key of its sampling
    weight, loaded weight), read from the loaded scene."""
    out = []
    if not lights:
        return out
    params = mi.traverse(scene)
    for i, light in enumerate(lights):
        key = f"{light_key(i)}.{EMITTER_POWER_PARAM[type(light)]}"
        wkey = f"{light_key(i)}.{EMITTER_WEIGHT_PARAM[type(light)]}"
        loaded = params[key]
        # copies: the parameter objects are replaced on update
        out.append((key, type(loaded)(loaded), wkey, float(params[wkey])))
    return out


def _sampling_weights(built, scales: tuple) -> tuple:
    """Lights that are off get no light samples (as if absent: 6 lights with 5 off would
    otherwise waste 5/6 of them); when every light is off the loaded weights stay."""
    if not any(k > 0 for k in scales):
        return tuple(e[3] for e in built.emitters)
    return tuple(e[3] if k > 0 else 0.0 for e, k in zip(built.emitters, scales))


def set_lighting(built, light_scales=None) -> None:
    """Put the loaded scene's lights at ``light_scales`` x their spec power (one factor per spec
    light, spec order; None = every light at its spec power).

    Parameters are touched only for lights whose factor differs from the scene's current state,
    so a spec that never changes its lighting renders exactly as loaded; each factor multiplies
    the loaded value, so going back to 1 restores it bit for bit and the result does not depend
    on the order in which views are rendered. A light at 0 stays in the scene as geometry (an
    area light's rectangle is still there, dark) but gets no light samples; lights on keep
    theirs, so scaling lights that stay on changes no sample (a factor of 2 doubles the image
    exactly)."""
    n = len(built.emitters)
    target = (1.0,) * n if light_scales is None else tuple(float(k) for k in light_scales)
    if len(target) != n:
        raise ValueError(f"expected {n} light factors (one per spec light), got {len(target)}")
    if not all(math.isfinite(k) and k >= 0 for k in target):
        raise ValueError(f"light factors must be finite and >= 0, got {target}")
    if target == built.light_scales:
        return
    params = mi.traverse(built.scene)
    weights_now, weights = _sampling_weights(built, built.light_scales), _sampling_weights(built, target)
    for (key, loaded, wkey, _), k, now, w, w_now in zip(built.emitters, target, built.light_scales,
                                                         weights, weights_now):
        if k != now:
            params[key] = loaded * k
        if w != w_now:
            params[wkey] = w
    params.update()
    built.light_scales = target
