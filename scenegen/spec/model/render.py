"""Render settings (the ``render:`` section) and what Mitsuba's samplers make of ``spp``."""
from __future__ import annotations

import math
from dataclasses import dataclass

from scenegen.errors import Where
from scenegen.geometry.color import BIT_DEPTHS
from scenegen.spec.model.meta import SEED_MAX, param, where_field
from scenegen.spec.model.limits import MAX_SPP

#: Allowed values of the enumerations, in the order the docs list them.
RENDER_VARIANTS = ("auto", "llvm_ad_rgb", "cuda_ad_rgb", "scalar_rgb")
SAMPLERS = ("ldsampler", "multijitter", "stratified", "orthogonal", "independent")
#: ``render.exr_compression`` (scenegen.dataset.codecs.exr.EXR_COMPRESSIONS; the spec does not
#: import the dataset layer, tests/scenegen/dataset/test_exr_compression.py keeps the two equal).
EXR_COMPRESSION_NAMES = ("zip", "zips", "rle", "none", "zstd")


def effective_spp(sampler: str, spp: int) -> int:
    """Samples per pixel Mitsuba 3.9's ``sampler`` actually takes when asked for ``spp`` (its
    plugins round the count up; tested against ``mi.load_dict(...).sample_count()`` in
    tests/test_render.py): ``ldsampler`` to a power of 4 (at least 4), ``orthogonal`` to the
    square of a prime, ``stratified`` to a square, ``multijitter`` to ``m * ceil(spp / m)`` with
    ``m = floor(sqrt(spp))``, ``independent`` not at all."""
    n = int(spp)
    if sampler == "ldsampler":
        k = 4
        while k < n:
            k *= 4
        return k
    if sampler == "orthogonal":
        p = 2
        while p * p < n or any(p % d == 0 for d in range(2, math.isqrt(p) + 1)):
            p += 1
        return p * p
    if sampler == "stratified":
        r = math.isqrt(n)
        return r * r if r * r == n else (r + 1) ** 2
    if sampler == "multijitter":
        m = math.isqrt(n)
        return m * -(-n // m)
    return n


@dataclass(frozen=True, kw_only=True)
class RenderSettings:
    spp: int = param(64, unit="samples per pixel", lo=1, hi=MAX_SPP)  # asked for; Mitsuba may round it up
    # (effective_spp)
    max_depth: int = param(6, unit="path segments, -1 = unbounded", lo=-1)  # longest light path
    # in segments (Mitsuba max_depth; -1 = unbounded; 0 is rejected)
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX)  # sampler seed (image noise);
    # independent of the scene seed
    variant: str = param("auto", unit="variant", choices=RENDER_VARIANTS)  # 'auto' lets the
    # renderer pick
    bit_depth: int = param(8, unit="bit depth", choices=BIT_DEPTHS)  # PNG bits per channel of the
    # rendered images
    sampler: str = param("ldsampler", unit="sampler", choices=SAMPLERS)  # Mitsuba sampler plugin
    motion_subframes: int = param(8, unit="sub-frames", lo=1, hi=256)  # sub-frames averaged when
    # objects move during the exposure
    exr_compression: str = param("zip", unit="EXR compression", choices=EXR_COMPRESSION_NAMES,
                                 omit_default=True)  # of a view's EXR files (truth, ids, linear):
    # all lossless; 'none' and 'zstd' trade size for the writer's CPU (docs/dataset_format.md)
    where: Where | None = where_field()
