"""The main job: a scene spec -> Mitsuba renders + exact per-pixel truth -> a dataset on disk."""
from __future__ import annotations

import hashlib
import json
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from scenegen.dataset.background import BackgroundWriter, writer_threads
from scenegen.dataset.cameras import ViewCamera
from scenegen.dataset.codecs import encode_json
from scenegen.dataset.layout import target_path
from scenegen.dataset.targets import target_document
from scenegen.dataset.view_files import software_versions
from scenegen.dataset.writer import DatasetWriter
from scenegen.imaging.stage import imaging_record, raw_view_record
from scenegen.pipeline.distributed import render_views_dask
from scenegen.pipeline.progress import ViewProgress
from scenegen.pipeline.sensors import write_streams
from scenegen.pipeline.stages import run_stage
from scenegen.pipeline.view import render_view_data, view_optics
from scenegen.render import load_scene
from scenegen.spec import load_spec, resolve_views, spec_sha256, spec_to_dict
from scenegen.spec.model import RenderSettings, effective_spp
from scenegen.spec.parse.read import option_in_range
from scenegen.spec.source import SpecSource
from scenegen.spec.views import light_scales_dict


@dataclass(frozen=True)
class RenderSettingsUsed:
    spp: int  # asked for (spec or --spp)
    spp_effective: int  # what the sampler takes per pixel (Mitsuba rounds some counts up)
    seed: int
    variant: str  # the resolved Mitsuba variant
    sampler: str
    max_depth: int
    bit_depth: int


@dataclass(frozen=True)
class RenderSummary:
    out_dir: Path
    views_total: int
    views_rendered: int
    views_skipped: int  # already complete (resume)
    seconds: float
    settings: RenderSettingsUsed


def parse_frames(text: str | None, n_frames: int) -> set[int] | None:
    """``'0-9,12'`` -> {0..9, 12} (frame indices, inclusive ranges); None = all frames."""
    if text is None:
        return None
    out: set[int] = set()
    for part in text.split(","):
        m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if not m:
            raise ValueError(f"--frames: expected indices or ranges like '0-9,12', got {part!r}")
        a = int(m.group(1))
        b = int(m.group(2)) if m.group(2) is not None else a
        if b < a or b >= n_frames:
            raise ValueError(f"--frames: range {part.strip()!r} is outside 0..{n_frames - 1}")
        out.update(range(a, b + 1))
    return out


def render_spec(spec_path, out_dir, *, frames: str | None = None, spp: int | None = None,
                seed: int | None = None, variant: str | None = None, resume: bool = False,
                progress: bool = True, dask_client=None, show_warnings: bool = True) -> RenderSummary:
    """Render every selected view of a spec into ``out_dir`` (see docs/dataset_format.md).

    ``spec_path``: a spec file, or a :class:`scenegen.spec.source.SpecSource` (e.g. a variant).
    ``dask_client``: a ``distributed.Client``; its workers render and write the views, this
    process records them in the run's order (scenegen/pipeline/distributed.py); None = render here.
    ``show_warnings``: the spec's warnings on stderr (``-q`` turns them off).

    Raises :class:`scenegen.errors.SpecError` for a bad spec, ``ValueError`` for bad options,
    :class:`scenegen.dataset.errors.DatasetError` for an unusable output directory.
    """
    source = spec_path if isinstance(spec_path, SpecSource) else None
    spec = source.load() if source is not None else load_spec(spec_path)
    for w in spec.warnings if show_warnings else ():  # e.g. a spec material replacing a mesh's own
        print(f"warning: {w}", file=sys.stderr)
    views = resolve_views(spec)
    n_frames = 1 + max((v.frame_index for v in views), default=-1)
    wanted = parse_frames(frames, n_frames)
    rs = spec.render
    spp = rs.spp if spp is None else option_in_range(RenderSettings, "spp", int(spp), "--spp")
    seed = rs.seed if seed is None else option_in_range(RenderSettings, "seed", int(seed), "--seed")

    t0 = time.perf_counter()
    built = load_scene(spec, variant=variant or rs.variant, spp=spp)
    for name, cam in built.cameras.items():
        if cam.mask_beyond_fold:
            n = int(cam.no_ray_mask().sum())
            print(f"camera {name!r}: {n} of {cam.width * cam.height} pixels "
                  f"({100 * n / (cam.width * cam.height):.2f} %) lie beyond the distortion's fold "
                  "radius (mask_beyond_fold): no ray, black, invalid in every truth map",
                  file=sys.stderr)
    used = RenderSettingsUsed(spp=spp, spp_effective=effective_spp(rs.sampler, spp), seed=seed,
                              variant=built.variant, sampler=rs.sampler, max_depth=rs.max_depth,
                              bit_depth=rs.bit_depth)
    # The run's identity: the spec plus every override that changes output bytes.
    run_hash = hashlib.sha256((spec_sha256(spec) + json.dumps(used.__dict__, sort_keys=True)).encode()).hexdigest()
    writer = DatasetWriter(out_dir, spec_sha256=run_hash, seed=seed, variant=used.variant,
                           versions=software_versions(), resume=resume)
    try:
        rendered, todo, skipped = _write_dataset(spec, views, wanted, built, writer, used, source or spec_path,
                                                 dask_client=dask_client, progress=progress)
    except BaseException:
        writer.discard()  # the folder goes only if this run created it and completed nothing in it
        raise
    return RenderSummary(Path(out_dir), len(todo), rendered, skipped, time.perf_counter() - t0, used)


def _write_dataset(spec, views, wanted, built, writer: DatasetWriter, used: RenderSettingsUsed, source, *,
                   dask_client, progress: bool) -> tuple[int, list, int]:
    """Everything :func:`render_spec` writes once the folder is locked: cameras.json, meshes,
    targets, the views, the cross-view and sequence stages; then the manifest is compacted.
    Returns (views rendered, views selected, views already complete)."""
    spp, seed = used.spp, used.seed
    if dask_client is not None:  # what a worker loads: the spec's text, shipped with each task
        source = source if isinstance(source, SpecSource) else SpecSource.from_path(source)
    view_cams = {v.name: ViewCamera(camera=built.cameras[v.camera], cam_from_world=v.cam_from_world,
                                       camera_name=v.camera, rig=v.rig, rig_member=v.rig_member,
                                       frame_index=v.frame_index, optics=view_optics(built, v),
                                       view_set=spec.view_sets[v.view_set].prefix,
                                       lights=light_scales_dict(spec, v.light_scales),
                                       raw=raw_view_record(spec.cameras[v.camera].imaging, v.name),
                                       time_s=v.time_s)
                 for v in views}  # all views, whatever --frames selects: cameras.json is the same for every run
    resolved = spec_to_dict(spec)
    resolved["render_used"] = dict(used.__dict__)
    resolved["objects_ids"] = built.objects
    if (imaging := imaging_record(spec, views)) is not None:
        resolved["imaging_used"] = imaging
    writer.write_cameras(view_cams, resolved)
    for name, mesh in built.meshes_world.items():
        writer.write_mesh(name, mesh)
    for name, (board, world_from_board) in built.boards.items():
        writer.write_file(target_path(name), encode_json(target_document(board, world_from_board)))

    todo = [(i, v) for i, v in enumerate(views) if wanted is None or v.frame_index in wanted]
    pending = [(index, v) for index, v in todo if not writer.is_complete(v.name)]
    skipped = len(todo) - len(pending)
    rendered = 0
    with ViewProgress(progress, len(todo)) as bar:
        for _ in range(skipped):
            bar.advance()
        if dask_client is not None:  # workers render and write; recorded here as their tasks finish
            rendered = render_views_dask(dask_client, source, writer, pending, spp=spp, seed=seed,
                                         variant=used.variant, on_done=bar.advance)
        else:  # views are encoded and written on a pool of threads while the next ones render
            with BackgroundWriter(writer, workers=writer_threads(render_on_cpu=not used.variant.startswith("cuda"))) \
                    as background:
                for index, v in pending:
                    image, linear, truth, extra = render_view_data(spec, built, index, v, spp=spp, seed=seed)
                    background.submit(v.name, image=image, linear_rgb=linear, truth=truth, extra_files=extra,
                                      exr_compression=spec.render.exr_compression)
                    del image, linear, truth, extra  # the writer holds the only references
                    rendered += 1
                    bar.advance()
    write_streams(spec, writer, built)  # the rig members that are not cameras, each by its sensor kind's writer
    for stage in ("crossview", "sequence"):  # cross-view truth, then truth across time (docs/crossview.md)
        run_stage(stage, spec, views, built, writer, spp=spp, seed=seed, variant=used.variant, client=dask_client,
                  source=source, progress=progress)
    writer.close()
    return rendered, todo, skipped
