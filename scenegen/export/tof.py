"""ToF raw frames as image files with their calibration (``scenegen export OUT --format tof``), per
ToF stream of the dataset (docs/dataset_format.md, "The ToF stream")::

    <stream>/raw/<frame>_f<i>_<psi>.png   16-bit grey PNG: the raw frame at frequency i and phase
                                          offset psi (000, 090, 180, 270 degrees), DN as read out
    <stream>/exr/<frame>.exr              float32 EXR: raw_f<i>_<psi> (DN), range, depth,
                                          amplitude_f<i>, valid, and the truth range_true,
                                          depth_true, multipath_error, mixing_error, flying,
                                          incidence (metres, degrees; 0/1 for masks)
    <stream>/calibration.json             intrinsics (the ToF camera's camera), frequencies,
                                          ambiguity ranges, phase offsets and the decoding rule,
                                          DN per electron, rig_from_sensor, and per frame its time
                                          and world_from_sensor

``<frame>`` is the sample index, 6 digits.
"""
from __future__ import annotations

import math

import numpy as np

from scenegen.dataset.codecs import encode_exr, encode_json, encode_png
from scenegen.export.common import each, name, write
from scenegen.export.errors import ExportError
from scenegen.geometry import tof as g

PHASES_DEG = tuple(round(math.degrees(p)) for p in g.PHASE_OFFSETS_RAD)
_TRUTH = {"range": "range_m", "depth": "depth_m", "range_true": "range_true_m", "depth_true": "depth_true_m",
          "multipath_error": "multipath_error_m", "mixing_error": "mixing_error_m", "incidence": "incidence_deg"}


def _member(spec: dict, sensor: str) -> dict:
    for rig in spec.get("rigs", {}).values():
        for m in rig.get("members", []):
            if m.get("kind") == "tof" and m.get("sensor") == sensor:
                return m
    raise ExportError(f"no rig member holds the ToF camera {sensor!r} in cameras.json")


def calibration(spec: dict, stream) -> dict:
    """The calibration document of one ToF stream (module docstring)."""
    tof = spec["sensors"]["tof"][stream.sensor]
    cam = spec["cameras"][tof["camera"]]
    freqs = [tof["frequency_mhz"] * 1e6] + ([tof["frequency2_mhz"] * 1e6] if tof.get("frequency2_mhz") else [])
    return {
        "stream": stream.name, "sensor": stream.sensor,
        "camera": {k: cam[k] for k in ("model", "width", "height", "fx", "fy", "cx", "cy", "skew", "dist", "K")},
        "frequencies_hz": freqs, "ambiguity_ranges_m": [g.ambiguity_range_m(f) for f in freqs],
        "phase_offsets_deg": list(PHASES_DEG),
        "decoding": "phi = atan2(C(90) - C(270), C(0) - C(180)) mod 2 pi; range = c phi / (4 pi f), c = 299792458 m/s "
                    "(docs/conventions.md, 'Time of flight')",
        "gain_dn_per_e": tof["gain_dn_per_e"], "black_level_dn": 0, "adc_bits": tof["adc_bits"],
        "rig_from_sensor": _member(spec, stream.sensor)["rig_from_sensor"],
        "frames": [{"index": k, "time_s": float(t), "world_from_sensor": T.tolist()}
                   for k, (t, T) in enumerate(zip(stream.time_s, stream.field("world_from_sensor")))],
    }


def export(ds, dest, progress=None) -> dict:
    streams = ds.streams.of_kind("tof")
    if not streams:
        raise ExportError(f"{ds.root} has no ToF stream (a rig member of kind tof)")
    files = 0
    for stream_name in each(streams, progress):
        s = ds.streams[stream_name]
        folder = name("stream", stream_name)
        raw, valid, flying, amp = s.field("raw_dn"), s.field("valid"), s.field("flying"), s.field("amplitude_e")
        truth = {key: s.field(field) for key, field in _TRUTH.items()}
        for k in range(s.samples):
            channels = {}
            for i in range(raw.shape[3]):
                channels[f"amplitude_f{i}"] = amp[k, ..., i].astype(np.float32)
                for j, psi in enumerate(PHASES_DEG):
                    write(dest, f"{folder}/raw/{k:06d}_f{i}_{psi:03d}.png", encode_png(raw[k, :, :, i, j]))
                    channels[f"raw_f{i}_{psi:03d}"] = raw[k, :, :, i, j].astype(np.float32)
                    files += 1
            channels |= {key: a[k].astype(np.float32) for key, a in truth.items()}
            channels |= {"valid": valid[k].astype(np.float32), "flying": flying[k].astype(np.float32)}
            write(dest, f"{folder}/exr/{k:06d}.exr", encode_exr(channels))
            files += 1
        write(dest, f"{folder}/calibration.json", encode_json(calibration(ds.cameras["spec"], s)))
        files += 1
    return {"files": files, "streams": list(streams)}
