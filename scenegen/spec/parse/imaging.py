"""``cameras.<name>.imaging``: the photometric chain (docs/image_formation.md), a preset of
:mod:`scenegen.imaging.presets` and/or explicit parameters; defaults are scenegen.imaging's."""
from __future__ import annotations

import dataclasses

from scenegen.imaging import ImagingParams, RawOutput, presets
from scenegen.imaging import seeds as imaging_seeds
from scenegen.located_yaml import Node
from scenegen.spec.model.meta import field_info, spec_fields
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import read_fields, read_given, read_value, yaml_keys

#: The parameter blocks (each a scenegen.imaging record); absent keys keep the preset's value.
BLOCKS = ("exposure", "vignetting", "sensor")
#: Read by hand: the preset (the base of the rest), ``bayer: none`` and ``white_balance: auto``
#: (None) and the raw outputs; ``bit_depth`` defaults to ``render.bit_depth``.
_BY_HAND = ("preset", "bayer", "white_balance", "raw")
KEYS = tuple(fi.key for fi in spec_fields(ImagingParams))
RAW_KEYS = yaml_keys(RawOutput)


def parse_imaging(node: Node, camera_name: str, ctx: ParseContext) -> ImagingParams:
    """Explicit keys override the preset's; ``bit_depth`` defaults to ``render.bit_depth``."""
    f = node.as_mapping("an imaging block (preset, exposure, vignetting, sensor, bayer, ...)")
    f.check(optional=KEYS)
    if "preset" in f:
        p = presets.PRESETS[read_value(f.get("preset"), field_info(ImagingParams, "preset"))]
    else:
        p = ImagingParams()
    parts = {}
    for block in BLOCKS:
        base = getattr(p, block)
        if block in f:
            bf = f.get(block).as_mapping(f"a mapping of {block} parameters").check(
                optional=yaml_keys(type(base)))
            base = dataclasses.replace(base, **read_given(bf, type(base)))
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
        pattern = read_value(f.get("bayer"), field_info(ImagingParams, "bayer"))
        pattern = None if pattern == "none" else pattern
    wb = p.white_balance
    if "white_balance" in f:
        wn = f.get("white_balance")
        if wn.is_sequence:
            wb = read_value(wn, field_info(ImagingParams, "white_balance"))
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
    given = read_given(f, ImagingParams, _BY_HAND)  # demosaic, response, gamma, bit_depth
    given.setdefault("bit_depth", ctx.render.bit_depth)
    return dataclasses.replace(p, **{**parts, "sensor": sensor}, bayer=pattern,
                               white_balance=wb, raw=raw, **given)


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
    out = RawOutput(**read_fields(f, RawOutput))
    if not any(getattr(out, k) for k in RAW_KEYS):
        raise node.error(f"raw: every output ({', '.join(RAW_KEYS)}) is off; write raw: false "
                         "(or remove it) for no raw files")
    return out
