"""The main job: a scene spec -> Mitsuba renders + exact per-pixel truth -> a dataset on disk."""
from __future__ import annotations

import hashlib
import json
import re
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from scenegen import dataset as ds
from scenegen import io as sio
from scenegen.spec import load_spec, resolve_views, spec_sha256, spec_to_dict
from scenegen.spec.views import light_scales_dict
from scenegen.textures import linear_to_srgb


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


def encode_image(linear_rgb: np.ndarray, bit_depth: int) -> np.ndarray:
    """Clean linear radiance -> sRGB-encoded uint8/uint16 (clipped at 1, rounded to nearest)."""
    top = (1 << bit_depth) - 1
    enc = np.clip(linear_to_srgb(np.clip(linear_rgb, 0.0, None)), 0.0, 1.0)
    return np.rint(enc * top).astype(np.uint8 if bit_depth == 8 else np.uint16)


def view_seed(seed: int, view_index: int) -> int:
    """Sampler seed of one view: distinct per view, fixed by (seed, index) (uint32)."""
    h = hashlib.sha256(f"{seed}:{view_index}".encode()).digest()
    return int.from_bytes(h[:4], "little")


def _truth_for_storage(truth: dict) -> dict:
    out = {}
    for k, v in truth.items():
        out[k] = v.astype(np.float32) if v.dtype == np.float64 else v
    return out


def render_spec(spec_path, out_dir, *, frames: str | None = None, spp: int | None = None,
                seed: int | None = None, variant: str | None = None, resume: bool = False,
                progress: bool = True, dask_client=None) -> RenderSummary:
    """Render every selected view of a spec into ``out_dir`` (see docs/dataset_format.md).

    ``spec_path``: a spec file, or a :class:`scenegen.variation.SpecSource` (e.g. a variant).
    ``dask_client``: a ``distributed.Client``; its workers render and write the views, this
    process records them in the run's order (scenegen/distributed.py); None = render here.

    Raises :class:`scenegen.errors.SpecError` for a bad spec, ``ValueError`` for bad options,
    :class:`scenegen.dataset.DatasetError` for an unusable output directory.
    """
    from scenegen.variation import SpecSource

    source = spec_path if isinstance(spec_path, SpecSource) else None
    spec = source.load() if source is not None else load_spec(spec_path)
    views = resolve_views(spec)
    n_frames = 1 + max((v.frame_index for v in views), default=-1)
    wanted = parse_frames(frames, n_frames)
    rs = spec.render
    spp = rs.spp if spp is None else int(spp)
    seed = rs.seed if seed is None else int(seed)
    if spp <= 0:
        raise ValueError(f"--spp must be positive, got {spp}")

    from scenegen.render.backend import load_mitsuba

    mi = load_mitsuba(variant or rs.variant)
    from scenegen.render.scene import build_scene

    from scenegen.spec.model import effective_spp

    used = RenderSettingsUsed(spp=spp, spp_effective=effective_spp(rs.sampler, spp), seed=seed,
                              variant=mi.variant(), sampler=rs.sampler, max_depth=rs.max_depth,
                              bit_depth=rs.bit_depth)
    # The run's identity: the spec plus every override that changes output bytes.
    run_hash = hashlib.sha256((spec_sha256(spec) + json.dumps(used.__dict__, sort_keys=True)).encode()).hexdigest()

    t0 = time.perf_counter()
    built = build_scene(spec, spp=spp, sampler=rs.sampler, max_depth=rs.max_depth)
    writer = ds.DatasetWriter(out_dir, spec_sha256=run_hash, seed=seed, variant=used.variant,
                              versions=ds.software_versions(), resume=resume)
    view_cams = {v.name: ds.ViewCamera(camera=built.cameras[v.camera], cam_from_world=v.cam_from_world,
                                       camera_name=v.camera, rig=v.rig, rig_member=v.rig_member,
                                       frame_index=v.frame_index, optics=view_optics(built, v),
                                       view_set=spec.view_sets[v.view_set].prefix,
                                       lights=light_scales_dict(spec, v.light_scales))
                 for v in views}  # all views, whatever --frames selects: cameras.json is the same for every run
    resolved = spec_to_dict(spec)
    resolved["render_used"] = dict(used.__dict__)
    resolved["objects_ids"] = built.objects
    from scenegen.imaging.stage import imaging_record  # docs/image_formation.md

    if (imaging := imaging_record(spec, views)) is not None:
        resolved["imaging_used"] = imaging
    writer.write_cameras(view_cams, resolved)
    for name, mesh in built.meshes_world.items():
        writer.write_mesh(name, mesh)
    for name, (board, world_from_board) in built.boards.items():
        writer.write_file(f"scene/targets/{name}.json", sio.encode_json(board_truth(board, world_from_board)))

    todo = [(i, v) for i, v in enumerate(views) if wanted is None or v.frame_index in wanted]
    skipped = sum(writer.is_complete(v.name) for _, v in todo)
    rendered = 0
    with _progress(progress, len(todo)) as bar:
        if dask_client is not None:  # workers render and write; recorded here in the run's order
            from scenegen.distributed import render_views_dask

            for _ in range(skipped):
                bar.advance()
            pending = [(index, v) for index, v in todo if not writer.is_complete(v.name)]
            rendered = render_views_dask(
                dask_client, source or SpecSource.from_path(spec_path), writer, pending, spp=spp,
                seed=seed, variant=used.variant, on_done=bar.advance)
        for index, v in todo if dask_client is None else ():
            if writer.is_complete(v.name):
                bar.advance()
                continue
            image, linear, truth, extra = render_view_data(spec, built, index, v, spp=spp, seed=seed)
            writer.write_view(v.name, image=image, linear_rgb=linear, truth=truth, extra_files=extra)
            rendered += 1
            bar.advance()
    from scenegen.crossview.stage import run_crossview  # cross-view truth (docs/crossview.md)

    run_crossview(spec, views, built, writer, encode_image=lambda lin: encode_image(lin, rs.bit_depth),
                  spp=spp, seed=seed)
    writer.close()
    return RenderSummary(Path(out_dir), len(todo), rendered, skipped, time.perf_counter() - t0, used)


def render_view_data(spec, built, index: int, v, *, spp: int, seed: int):
    """One view's (image, linear_rgb, truth as stored, extra files or None), ready for
    :func:`scenegen.dataset.encode_view`; ``index`` is the view's position in the run's order."""
    from scenegen.imaging.stage import apply_imaging
    from scenegen.render.scene import render_view
    from scenegen.render.truth import truth_pass

    linear = render_view(built, v.camera, v.cam_from_world, spp=spp, seed=view_seed(seed, index),
                         motion=v.motion, light_scales=v.light_scales)
    truth = truth_pass(built.scene, built.cameras[v.camera], v.cam_from_world, built.id_tables,
                       row_poses=rolling_shutter_rows(built, v))
    params = spec.cameras[v.camera].imaging
    if params is None:  # clean path: sRGB encoding of the linear render
        image, extra = encode_image(linear, spec.render.bit_depth), None
    else:  # the camera's photometric chain; its vignetting map is saved as truth
        image, extra = apply_imaging(linear, params, built.cameras[v.camera], spec.seed, index, v.name)
    return image, linear, _truth_for_storage(truth), extra


def rolling_shutter_rows(built, view):
    """Per-row ``cam_from_world`` for a moving camera with a rolling shutter, else None."""
    from scenegen.optics import row_poses

    shutter = getattr(built.optics.get(view.camera), "shutter", None)
    if shutter is None or shutter.rolling_readout_s == 0 or view.motion is None or view.motion.is_static:
        return None
    return row_poses(view.cam_from_world, view.motion, shutter, built.cameras[view.camera].height)


def view_optics(built, view) -> dict | None:
    """What cameras.json records of a view's lens and time effects (None if it has none)."""
    from scenegen.optics import motion_to_dict

    optics = built.optics.get(view.camera)
    d = optics.to_dict() if optics is not None else {}
    if view.motion is not None and not view.motion.is_static:
        d["camera_motion"] = {**motion_to_dict(view.motion), "frame": "camera (OpenCV axes), body velocities; "
                              "world_from_cam(tau) = world_from_cam @ [exp(w tau) | v tau], tau from mid-exposure"}
    ca = getattr(optics, "chromatic_aberration", None)
    if ca is not None:
        d["channel_cameras"] = {c: cam.to_dict() for c, cam in zip("RGB", ca.channel_cameras(built.cameras[view.camera]))}
    return d or None


def board_truth(board, world_from_board) -> dict:
    """A calibration target's exact points: board frame and world frame (metres)."""
    pts = np.asarray(board.points_board, dtype=np.float64)
    d = {"kind": board.kind, "size_m": list(map(float, board.size_m)),
         "world_from_board": world_from_board.to_dict(),
         "point_ids": np.asarray(board.point_ids).tolist(),
         "points_board": pts.tolist(), "points_world": world_from_board.apply(pts).tolist(),
         "frame": "board: origin at the top-left physical corner, x along the picture's columns,"
                  " y along its rows, z = 0 on the surface"}
    for extra in ("marker_ids", "marker_corners_board"):
        if getattr(board, extra, None) is not None:
            d[extra] = np.asarray(getattr(board, extra)).tolist()
    return d


class _progress:
    """A rich progress bar with frames/s (nothing when disabled)."""

    def __init__(self, enabled: bool, total: int):
        self.enabled, self.total = enabled, total
        self._p = None
        self._done = 0
        self._t0 = time.perf_counter()

    def __enter__(self):
        if self.enabled:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

            self._p = Progress(TextColumn("rendering"), BarColumn(), MofNCompleteColumn(),
                               TextColumn("{task.fields[fps]}"), TimeRemainingColumn())
            self._p.start()
            self._task = self._p.add_task("render", total=self.total, fps="")
        return self

    def advance(self):
        self._done += 1
        if self._p is not None:
            fps = self._done / max(time.perf_counter() - self._t0, 1e-9)
            self._p.update(self._task, advance=1, fps=f"{fps:.2f} frames/s")

    def __exit__(self, *exc):
        if self._p is not None:
            self._p.stop()
