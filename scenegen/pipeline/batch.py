"""Runs of many scenes or on many workers: ``scenegen render --variants N --workers N``.

``variants=N`` renders variants 0..N-1 of a spec (:func:`scenegen.spec.variants.derive_variant`),
each a complete dataset in ``OUT/variant_0000``, ``OUT/variant_0001``, ...; the variant specs
are all derived and checked before the first render, so an impossible draw fails early.
``workers``/``scheduler`` render views on Dask workers (:mod:`scenegen.pipeline.distributed`); the same
client serves every variant, and a worker keeps the scenes it loaded.
"""
from __future__ import annotations

import contextlib
from pathlib import Path

from scenegen.pipeline.distributed import open_client
from scenegen.pipeline.run import render_spec
from scenegen.spec.source import SpecSource
from scenegen.spec.variants import derive_variant, variant_dir_name

__all__ = ["render_many"]


def render_many(spec_path, out_dir, *, variants: int | None = None, workers: int | None = None,
                scheduler: str | None = None, **render_kw) -> list:
    """Render the spec (or its ``variants`` variants) into ``out_dir``; returns the
    :class:`scenegen.pipeline.run.RenderSummary` of each dataset. ``render_kw`` go to
    :func:`scenegen.pipeline.run.render_spec` (frames, spp, seed, variant, resume, progress,
    show_warnings)."""
    if variants is not None and variants < 1:
        raise ValueError(f"--variants must be at least 1, got {variants}")
    if workers is not None and scheduler is not None:
        raise ValueError("give only one of --workers and --scheduler")
    base = SpecSource.from_path(spec_path)
    if variants is None:
        jobs = [(base, Path(out_dir))]
    else:
        spec = base.load()
        for i in range(variants):  # every variant is drawn and checked before anything renders
            derive_variant(spec, i)
        jobs = [(SpecSource(base.text, base.file, base.base_dir, i), Path(out_dir) / variant_dir_name(i))
                for i in range(variants)]
    if workers is None and scheduler is None:
        ctx = contextlib.nullcontext(None)
    else:
        ctx = open_client(workers=workers, scheduler=scheduler)
    with ctx as client:
        return [render_spec(src, out, dask_client=client, **render_kw) for src, out in jobs]
