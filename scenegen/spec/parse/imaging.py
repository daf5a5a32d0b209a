"""``cameras.<name>.imaging``: the photometric chain (docs/image_formation.md), a preset of
:mod:`scenegen.imaging.presets` and/or explicit parameters; defaults are scenegen.imaging's."""
from __future__ import annotations

import dataclasses

from scenegen.geometry.color import BIT_DEPTHS
from scenegen.imaging import ImagingParams, RawOutput, bayer, presets, response
from scenegen.imaging import seeds as imaging_seeds
from scenegen.located_yaml import Node
from scenegen.spec.model.meta import SEED_MAX
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_bool

KEYS = ("preset", "exposure", "vignetting", "sensor", "bayer", "demosaic", "white_balance",
        "response", "gamma", "bit_depth", "raw")
RAW_KEYS = tuple(f.name for f in dataclasses.fields(RawOutput))
_POS = dict(lo=0.0, lo_open=True)
#: key -> reader(node) of each sub-block of parameters; absent keys keep the preset's value.
BLOCKS = {
    "exposure": {
        "exposure_time_s": lambda n: n.as_float("seconds", **_POS),
        "f_number": lambda n: n.as_float("f-number", **_POS),
        "lens_transmittance": lambda n: n.as_float("fraction", lo=0.0, lo_open=True, hi=1.0),
        "gain_db": lambda n: n.as_float("dB", lo=-60.0, hi=60.0)},
    "vignetting": {
        "natural_cos4": lambda n: n.as_bool(),
        "coeffs": lambda n: n.as_floats(3, "a1, a2, a3 of 1 + a1 r^2 + a2 r^4 + a3 r^6"),
        "center_px": lambda n: n.as_floats(2, "u, v in pixels")},
    "sensor": {
        "pixel_pitch_um": lambda n: n.as_float("micrometres", **_POS),
        "quantum_efficiency": lambda n: n.as_floats(3, "R, G, B fractions", lo=0.0, hi=1.0),
        "wavelengths_nm": lambda n: n.as_floats(3, "R, G, B nanometres", **_POS),
        "system_gain_dn_per_e": lambda n: n.as_float("DN per electron", **_POS),
        "dark_noise_e": lambda n: n.as_float("electrons", lo=0.0),
        "dark_current_e_per_s": lambda n: n.as_float("electrons per second", lo=0.0),
        "saturation_capacity_e": lambda n: n.as_float("electrons", **_POS),
        "prnu_percent": lambda n: n.as_float("percent", lo=0.0, hi=100.0),
        "dsnu_e": lambda n: n.as_float("electrons", lo=0.0),
        "black_level_dn": lambda n: n.as_int("DN", lo=0),
        "black_level_clip": lambda n: n.as_bool(),
        "adc_bits": lambda n: n.as_int("bits", lo=1, hi=16),
        "temporal_noise": lambda n: n.as_bool(),
        "fixed_pattern_seed": lambda n: n.as_int(lo=0, hi=SEED_MAX)},
}


def parse_imaging(node: Node, camera_name: str, ctx: ParseContext) -> ImagingParams:
    """Explicit keys override the preset's; ``bit_depth`` defaults to ``render.bit_depth``."""
    f = node.as_mapping("an imaging block (preset, exposure, vignetting, sensor, bayer, ...)")
    f.check(optional=KEYS)
    if "preset" in f:
        name = f.get("preset").as_enum(tuple(presets.PRESETS), "imaging preset")
        p = presets.PRESETS[name]
    else:
        p = ImagingParams()
    parts = {}
    for block, readers in BLOCKS.items():
        base = getattr(p, block)
        if block in f:
            bf = f.get(block).as_mapping(f"a mapping of {block} parameters").check(
                optional=tuple(readers))
            base = dataclasses.replace(base, **{k: r(bf.get(k)) for k, r in readers.items()
                                                if k in bf})
        parts[block] = base
    sensor = parts["sensor"]
    sf = f.get("sensor").as_mapping() if "sensor" in f else None
    if sf is None or "fixed_pattern_seed" not in sf:  # PRNU / DSNU fixed per camera name
        sensor = dataclasses.replace(
            sensor, fixed_pattern_seed=imaging_seeds.fixed_pattern_seed_for(camera_name))
    if sensor.black_level_dn >= sensor.white_level_dn:
        where = (sf.get("black_level_dn") or sf.get("adc_bits")) if sf is not None else None
        raise (where or node).error(f"expected black_level_dn < 2^adc_bits - 1 = "
                                    f"{sensor.white_level_dn}, got {sensor.black_level_dn}")
    pattern = p.bayer
    if "bayer" in f:
        pattern = f.get("bayer").as_enum(bayer.PATTERNS + ("none",), "Bayer pattern")
        pattern = None if pattern == "none" else pattern
    wb = p.white_balance
    if "white_balance" in f:
        wn = f.get("white_balance")
        if wn.is_sequence:
            wb = wn.as_floats(3, "R, G, B gains", lo=0.0, lo_open=True)
        else:
            wn.as_enum(("auto",), "white balance: 3 gains or auto")
            wb = None  # auto: equal-radiance white comes out neutral
    raw = p.raw
    if "raw" in f:
        raw = parse_raw(f.get("raw"))
        if raw is not None and pattern is None:
            where = f.get("bayer") if "bayer" in f else f.get("raw")
            raise where.error("raw output is the colour filter mosaic; with bayer: none there is "
                              "none (give a Bayer pattern, or remove raw)")
    return dataclasses.replace(
        p, exposure=parts["exposure"], vignetting=parts["vignetting"], sensor=sensor,
        bayer=pattern, white_balance=wb, raw=raw,
        demosaic=f.get("demosaic").as_enum(bayer.DEMOSAIC_METHODS, "demosaic method")
        if "demosaic" in f else p.demosaic,
        response=f.get("response").as_enum(response.RESPONSES, "camera response")
        if "response" in f else p.response,
        gamma=f.float("gamma", p.gamma, "exponent", lo=0.0, lo_open=True),
        bit_depth=f.get("bit_depth").as_enum(BIT_DEPTHS, "bit depth") if "bit_depth" in f
        else ctx.render.bit_depth)


def parse_raw(node: Node) -> RawOutput | None:
    """``raw: true`` (the defaults), ``raw: false`` (none) or ``raw: {dng: bool, png: bool}``."""
    if not node.is_mapping:
        v = node.scalar() if not node.is_sequence else None
        if not isinstance(v, bool):
            raise node.error("expected true, false or a mapping {dng: true/false, png: "
                             f"true/false}}, got {node.describe()}")
        return RawOutput() if v else None
    f = node.as_mapping("raw outputs: {dng: true/false, png: true/false}, or true / false")
    f.check(optional=RAW_KEYS)
    out = RawOutput(**{k: read_bool(f, RawOutput, k) for k in RAW_KEYS})
    if not any(getattr(out, k) for k in RAW_KEYS):
        raise node.error(f"raw: every output ({', '.join(RAW_KEYS)}) is off; write raw: false "
                         "(or remove it) for no raw files")
    return out
