"""The imaging chain as a pipeline stage: per-view application and the record for cameras.json.

Kept apart from :mod:`.chain` (pure arrays) so the chain never depends on the spec or dataset.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from scenegen.dataset.codecs.dng import encode_dng
from scenegen.dataset.codecs.exr import encode_exr
from scenegen.dataset.codecs.png import encode_png
from scenegen.dataset.layout import (
    VIGNETTING_CHANNEL,
    VIGNETTING_TEMPLATE,
    raw_dng_path,
    raw_png_path,
    vignetting_path,
)
from scenegen.dataset.raw import dng_of, raw_record
from scenegen.imaging import seeds
from scenegen.imaging.chain import (
    apply_chain,
    electrons_per_radiance,
    isp_stages,
    neutral_white_balance,
    white_balance_gains,
)
from scenegen.imaging.raw import as_shot_neutral, color_matrix_xyz_to_camera


def apply_imaging(linear_rgb: np.ndarray, params, camera, scene_seed: int, view_index: int,
                  view: str, *, camera_name: str) -> tuple[np.ndarray, dict[str, bytes]]:
    """One view's delivered image and its extra files ``{relative path: bytes}``: the
    vignetting map (EXR) and, with ``params.raw``, the raw mosaic (DNG and/or 16-bit PNG)."""
    result = apply_chain(linear_rgb, params, camera, seeds.frame_seed(scene_seed, view_index))
    extra = {vignetting_path(view): encode_exr({VIGNETTING_CHANNEL: result.vignetting})}
    record = raw_view_record(params, view)
    if record is not None:
        files = record["files"]
        if "dng" in files:
            extra[files["dng"]] = encode_dng(dng_of(result.raw_dn, record, dng_camera_model(
                params, camera_name)))
        if "png" in files:
            extra[files["png"]] = encode_png(result.raw_dn)
    return result.image, extra


def dng_camera_model(params, camera_name: str) -> str:
    """The DNG UniqueCameraModel of a camera: 'scenegen <preset or custom> <camera name>'."""
    return f"scenegen {params.preset or 'custom'} {camera_name}"


def raw_view_record(params, view: str) -> dict[str, Any] | None:
    """``views.<view>.raw`` of cameras.json for a camera with ``imaging.raw`` (else None): the
    raw files, CFA, black and white levels, the colour data of the DNG and the ISP stages that
    turn the mosaic into images/<view>.png."""
    if params is None or params.raw is None:
        return None
    raw = params.raw
    if params.bayer is None:
        raise ValueError("raw output needs a colour filter mosaic (bayer is none)")
    s = params.sensor
    files = {k: path(view) for k, path, on in (("dng", raw_dng_path, raw.dng),
                                               ("png", raw_png_path, raw.png)) if on}
    return raw_record(files=files, cfa_pattern=params.bayer, black_level_dn=s.black_level_dn,
                      white_level_dn=s.white_level_dn, adc_bits=s.adc_bits,
                      black_level_clipped=s.black_level_clip,
                      as_shot_neutral=as_shot_neutral(white_balance_gains(params)),
                      color_matrix=color_matrix_xyz_to_camera(electrons_per_radiance(params)),
                      isp=isp_stages(params))


def imaging_record(spec, views) -> dict[str, Any] | None:
    """What a reader needs, besides the resolved spec's ``cameras.<name>.imaging``, to reproduce
    every view's chain: derived constants per camera and the frame seed of every view (None when
    no camera has an imaging block)."""
    cams = {name: c.imaging for name, c in spec.cameras.items() if c.imaging is not None}
    if not cams:
        return None
    return {
        "doc": "docs/image_formation.md",
        "seed_rule": "frame_seed = scenegen.imaging.seeds.frame_seed(spec seed, view index); "
                     "temporal draws default_rng(SeedSequence([frame_seed, crc32(stage)])), "
                     "PRNU/DSNU default_rng(SeedSequence([fixed_pattern_seed, crc32(stage)]))",
        "cameras": {name: {
            "electrons_per_radiance": [float(x) for x in electrons_per_radiance(p)],
            "system_gain_dn_per_e": p.sensor.system_gain(p.exposure.gain_db),
            "white_balance_used": list(p.white_balance if p.white_balance is not None
                                       else neutral_white_balance(p)),
            "vignetting_file": VIGNETTING_TEMPLATE,
        } for name, p in cams.items()},
        "view_frame_seeds": {v.name: seeds.frame_seed(spec.seed, i)
                             for i, v in enumerate(views) if v.camera in cams},
    }
