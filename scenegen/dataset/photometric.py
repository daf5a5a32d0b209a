"""Albedo and light truth as stored (docs/dataset_format.md, "Albedo and light truth").

* ``truth/<view>_albedo.exr``: float32 channels ``albedo.R``, ``albedo.G``, ``albedo.B``: the
  diffuse reflectance (in [0, 1], linear RGB) of the surface each pixel centre's ray hits, NaN
  where it hits nothing.
* ``truth/<view>_lights.json``: ``{"format": "scenegen.lights/1", "frame", "view", "lights":
  [...]}``, every light on in the view, camera frame (OpenCV axes); a directional light has
  ``direction_to_light_cam`` (unit), ``irradiance_w_m2`` and ``intensity`` (= irradiance / pi,
  per channel), a point light ``position_cam`` and ``intensity_w_sr`` (scenegen.spec.light_truth
  writes them).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset.codecs.exr import encode_exr, pack_channels, unpack_channels

ALBEDO_PREFIX = "albedo"
ALBEDO_CHANNELS = ("R", "G", "B")
LIGHTS_FORMAT = "scenegen.lights/1"


def encode_albedo(albedo: np.ndarray) -> bytes:
    """(H, W, 3) float albedo -> EXR bytes (float32)."""
    a = np.asarray(albedo)
    if a.ndim != 3 or a.shape[2] != 3 or not np.issubdtype(a.dtype, np.floating):
        raise ValueError(f"albedo must be a float (H, W, 3) array, got {a.dtype} {a.shape}")
    return encode_exr(pack_channels(ALBEDO_PREFIX, a.astype(np.float32, copy=False), ALBEDO_CHANNELS))


def decode_albedo(channels) -> np.ndarray:
    """Decoded EXR channels -> (H, W, 3) float32 albedo (KeyError naming a missing channel)."""
    return unpack_channels(channels, ALBEDO_PREFIX, ALBEDO_CHANNELS)


@dataclass(frozen=True, kw_only=True)
class ViewLight:
    """One light on in a view, in the view's camera frame (OpenCV axes). Fields a light type does
    not have are None."""

    name: str
    type: str  # directional, point, spot, area, constant, envmap
    factor: float  # the view's factor on the light's spec power (already in the values below)
    direction_to_light_cam: tuple[float, float, float] | None = None  # unit (directional)
    irradiance_w_m2: tuple[float, float, float] | None = None  # linear RGB (directional)
    intensity: tuple[float, float, float] | None = None  # irradiance / pi (directional)
    position_cam: tuple[float, float, float] | None = None  # metres (point, spot)
    intensity_w_sr: tuple[float, float, float] | None = None  # W/sr (point, spot)


_VECTORS = ("direction_to_light_cam", "irradiance_w_m2", "intensity", "position_cam", "intensity_w_sr")


def decode_lights(doc, source: str) -> tuple[ViewLight, ...]:
    """The lights of a parsed lights document; ValueError naming ``source`` and the field when it
    is not one."""
    if not isinstance(doc, dict) or doc.get("format") != LIGHTS_FORMAT or not isinstance(doc.get("lights"), list):
        raise ValueError(f"{source}: expected a {LIGHTS_FORMAT} document with a 'lights' list")
    out = []
    for i, d in enumerate(doc["lights"]):
        where = f"{source}: lights[{i}]"
        if not isinstance(d, dict) or not isinstance(d.get("name"), str) or not isinstance(d.get("type"), str):
            raise ValueError(f"{where}: expected a mapping with 'name' and 'type'")
        kw = {}
        for key in _VECTORS:
            if key in d:
                v = d[key]
                if not (isinstance(v, list) and len(v) == 3 and all(isinstance(x, (int, float)) for x in v)
                        and np.isfinite(v).all()):
                    raise ValueError(f"{where}.{key}: expected 3 finite numbers, got {v!r}")
                kw[key] = tuple(float(x) for x in v)
        factor = d.get("factor")
        if not isinstance(factor, (int, float)) or not np.isfinite(factor) or factor < 0:
            raise ValueError(f"{where}.factor: expected a finite number >= 0, got {factor!r}")
        out.append(ViewLight(name=d["name"], type=d["type"], factor=float(factor), **kw))
    return tuple(out)
