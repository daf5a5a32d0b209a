"""The imaging chain as a pipeline stage: per-view application and the record for cameras.json.

Kept apart from :mod:`.chain` (pure arrays) so the chain never depends on the spec or dataset.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from scenegen.dataset.codecs.exr import encode_exr
from scenegen.dataset.layout import VIGNETTING_CHANNEL, VIGNETTING_TEMPLATE, vignetting_path
from scenegen.imaging import seeds
from scenegen.imaging.chain import apply_chain, electrons_per_radiance, neutral_white_balance


def apply_imaging(linear_rgb: np.ndarray, params, camera, scene_seed: int, view_index: int,
                  view: str) -> tuple[np.ndarray, dict[str, bytes]]:
    """One view's delivered image and its extra truth files ``{relative path: EXR bytes}``."""
    result = apply_chain(linear_rgb, params, camera, seeds.frame_seed(scene_seed, view_index))
    extra = {vignetting_path(view): encode_exr({VIGNETTING_CHANNEL: result.vignetting})}
    return result.image, extra


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
