"""The sequence stage of the pipeline: runs after every view of a sequence is rendered and writes
its truth across time (docs/crossview.md, "Sequences") through the dataset writer: every
object's pose per frame, flow / scene flow / occlusion for frame pairs (k, k + step) of each
camera stream both ways, point tracks, and for a stereo rig with rectified frames the scene flow
truth on the rectified left grid (:mod:`.stereo_sequence`).

Truth points of frame a come from the truth pass at a's time in float64 (centre + range * ray,
range from the float32 intersection); b's visibility casts name b's time
(:class:`scenegen.render.caster.Caster`). Only complete views take part; the index is
written when every view is complete.
"""
from __future__ import annotations

import warnings

from collections import OrderedDict
from dataclasses import dataclass

import numpy as np

from scenegen.crossview.frames import FrameGeometry
from scenegen.crossview.motion import frame_motion
from scenegen.crossview.tracks import track_points
from scenegen.dataset.codecs import TrackSet, encode_exr, encode_flo, encode_json, encode_tracks
from scenegen.dataset.crossview import STATE_NAMES
from scenegen.dataset.layout import (
    SEQUENCE_INDEX,
    SEQUENCE_OBJECTS,
    motion_path,
    sequence_flow_path,
    stereo_motion_path,
    tracks_path,
)
from scenegen.dataset.sequence import (
    SCENE_FLOW_FRAME,
    SEQUENCE_FORMAT,
    SEQUENCE_FORMAT_VERSION,
    encode_motion_channels,
    encode_stereo_motion_channels,
    objects_document,
)
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.seeds import hashed_seed32
from scenegen.pipeline.pairs import streams
from scenegen.pipeline.stereo_sequence import StereoSequence, stereo_pairs
from scenegen.pipeline.view import correspond_fn, rolling_rows, rolling_shutter_rows, view_truth, visibility_fn
from scenegen.spec.timeline import Timeline


class SequenceTruth:
    """Truth of a sequence's frames: float64 points, object ids, poses, visibility at a time."""

    def __init__(self, spec, built, keep_frames: int = 8):
        self.spec, self.built = spec, built
        self.timeline = Timeline(spec)
        self._frames: OrderedDict = OrderedDict()  # the last keep_frames frames' points (bounded memory)
        self.keep_frames = max(2, int(keep_frames))
        self._geometry: dict = {}

    def frame(self, view) -> tuple[np.ndarray, np.ndarray]:
        """((H, W, 3) float64 world points, NaN = no surface; (H, W) uint32 object ids) of a view."""
        if view.name not in self._frames:
            t = view_truth(self.built, view)  # at the view's time
            cam = self.built.cameras[view.camera]
            if rolling_shutter_rows(self.built, view) is None:
                wfc = view.cam_from_world.inverse()
                rays, R = self.built.camera_rays(cam), wfc.R
                rng = np.where(t[TruthKind.VALID], t[TruthKind.RANGE], np.nan).reshape(-1)
                # per component, without a BLAS call (no thread pool next to Dr.Jit's)
                P = np.empty((len(rng), 3))
                for i in range(3):
                    P[:, i] = wfc.t[i] + rng * (R[i, 0] * rays[:, 0] + R[i, 1] * rays[:, 1] + R[i, 2] * rays[:, 2])
                P = P.reshape(cam.height, cam.width, 3)
            else:  # per-row poses: the kernel's float32 points
                P = np.where(t[TruthKind.VALID][..., None], t[TruthKind.POINTS_WORLD], np.nan).astype(np.float64)
            self._frames[view.name] = (P, t[TruthKind.OBJECT_ID].copy())
            while len(self._frames) > self.keep_frames:
                self._frames.popitem(last=False)
        self._frames.move_to_end(view.name)
        return self._frames[view.name]

    def poses(self, view):
        return self.timeline.poses_by_id(view.time_s)

    def geometry(self, view) -> FrameGeometry:
        """The frame as the truth across time sees it (its rolling shutter's rows included)."""
        if view.name not in self._geometry:
            rows = rolling_rows(self.built, view)
            self._geometry[view.name] = FrameGeometry(self.poses(view), self.built.cameras[view.camera],
                                                      view.cam_from_world, visibility_fn(self.built, view, rows), rows,
                                                      correspond_fn(self.built, view))
        return self._geometry[view.name]

    def motion(self, a, b):
        P, ids = self.frame(a)
        return frame_motion(P, ids, self.geometry(a), self.geometry(b))


def stream_name(vs_prefix: str, member: str | None) -> str:
    return vs_prefix if member is None else f"{vs_prefix}_{member}"


def query_pixels(ids: np.ndarray, valid: np.ndarray, animated_ids, count: int, seed: int) -> np.ndarray:
    """(n, 2) int pixels (x, y) of a query frame: up to half on animated objects (where any is
    seen), the rest elsewhere on surfaces, without repeats, drawn with default_rng(seed)."""
    rng = np.random.default_rng(seed)
    flat = np.flatnonzero(valid.ravel())
    moving = np.isin(ids.ravel()[flat], np.asarray(sorted(animated_ids), np.uint32))
    on_moving, still = flat[moving], flat[~moving]
    n_moving = min(len(on_moving), count // 2 if len(still) else count)
    n_still = min(len(still), count - n_moving)
    pick = np.concatenate([rng.choice(on_moving, n_moving, replace=False),
                           rng.choice(still, n_still, replace=False)]).astype(np.int64)
    W = valid.shape[1]
    return np.stack([pick % W, pick // W], 1)


def stream_tracks(st: SequenceTruth, vs, name: str, cfg) -> TrackSet:
    """The tracks of one stream (frames ``vs`` in order)."""
    frames = [st.geometry(v) for v in vs]
    animated = {o.object_id for o in st.spec.objects if o.animation is not None}
    qs = [q for q in cfg.query_frames if q < len(vs)]
    queries, groups = [], []
    for i, q in enumerate(qs):
        P, ids = st.frame(vs[q])
        n = cfg.count // len(qs) + (1 if i < cfg.count % len(qs) else 0)
        px = query_pixels(ids, np.isfinite(P[..., 0]), animated, n, hashed_seed32(cfg.seed, name, q))
        groups.append((P[px[:, 1], px[:, 0]], ids[px[:, 1], px[:, 0]], st.geometry(vs[q]), px[:, 1]))
        queries.append(np.column_stack([np.full(len(px), q), px[:, 1], px[:, 0]]))
    got = sum(len(q) for q in queries)
    if got < cfg.count:  # fewer surface pixels than asked for: said, not silent
        warnings.warn(f"sequence.tracks.count: stream {name!r}: {got:,} of {cfg.count:,} tracks written; its query "
                      f"frames {list(qs)} show only {got:,} surface pixels to start a track at", RuntimeWarning,
                      stacklevel=2)
    xy, occ, oof = track_points(groups, frames)  # each frame's scene cast once for every query
    cam = st.built.cameras[vs[0].camera]
    return TrackSet(query_points=np.concatenate(queries), tracks_xy=xy, occluded=occ, out_of_frame=oof,
                    image_size=np.array([cam.width, cam.height]), frame_names=np.array([v.name for v in vs]))


@dataclass(frozen=True)
class SequencePlan:
    """The stage's items in the order they run best (each target frame's scene moved once):
    ``("motion", a, b)`` (view names: motion truth a -> b and its .flo), ``("tracks", stream,
    frames)``, ``("stereo_motion", (left a, right a), (left b, right b))`` (both ways); ``index``:
    the index without its file list; ``whole``: every view is complete (the index is written)."""

    items: tuple[tuple, ...]
    index: dict
    whole: bool
    keep_frames: int


def plan_sequence(spec, views, is_complete) -> SequencePlan | None:
    """The items of the sequence truth of ``spec.sequence`` (None for a static spec), for the
    views ``is_complete(name)`` says are written."""
    seq = getattr(spec, "sequence", None)
    if seq is None:
        return None
    names = {v.name for v in views if is_complete(v.name)}
    index = {"format": SEQUENCE_FORMAT, "format_version": SEQUENCE_FORMAT_VERSION,
             "timestamps_s": list(seq.timestamps_s), "scene_flow_frame": SCENE_FLOW_FRAME,
             "state_codes": {str(k): v for k, v in STATE_NAMES.items()}, "pairs": [], "tracks": []}
    items = []
    for (set_index, member), vs in streams(views).items():
        name = stream_name(spec.view_sets[set_index].prefix, member)
        jobs = []  # (position of the target frame, source, target): one scene move per target
        for step in seq.flow_steps:
            for k, (a, b) in enumerate(zip(vs, vs[step:])):
                if a.name not in names or b.name not in names:
                    continue
                jobs += [(k + step, a, b), (k, b, a)]
                index["pairs"].append({"a": a.name, "b": b.name, "step": step})
        items += [("motion", i.name, j.name) for _, i, j in sorted(jobs, key=lambda job: job[0])]
        if seq.tracks is not None and all(v.name in names for v in vs):
            items.append(("tracks", name, tuple(v.name for v in vs)))
            index["tracks"].append({"stream": name, "frames": [v.name for v in vs]})
    jobs = stereo_pairs(spec, views, names, seq.flow_steps)
    if jobs:  # only then the key: sequences without rectified stereo keep their index bytes
        index["stereo_pairs"] = [{"a": fa[0].name, "b": fb[0].name, "step": step} for step, fa, fb in jobs]
        items += [("stereo_motion", tuple(v.name for v in fa), tuple(v.name for v in fb)) for _, fa, fb in jobs]
    return SequencePlan(tuple(items), index, len(names) == len(views), 2 * max(seq.flow_steps) + 2)


class SequenceContext:
    """What the sequence items share where they run: the views by name, the frames' truth (the
    last ``keep_frames`` frames cached) and ``sink`` (``write_file(rel, data)``)."""

    def __init__(self, spec, views, built, sink, *, keep_frames: int):
        self.spec, self.sink = spec, sink
        self.views = {v.name: v for v in views}
        # frames a step away on both sides stay cached while the targets are walked in order
        self.st = SequenceTruth(spec, built, keep_frames=keep_frames)
        self._stereo = None
        self.keep_frames = keep_frames

    @property
    def stereo(self) -> StereoSequence:
        if self._stereo is None:
            self._stereo = StereoSequence(self.st, keep_frames=self.keep_frames)
        return self._stereo


def execute_sequence_item(ctx: SequenceContext, item: tuple) -> None:
    """Write one item's files through ``ctx``."""
    kind, a, b = item
    if kind == "motion":
        m = ctx.st.motion(ctx.views[a], ctx.views[b])
        ctx.sink.write_file(motion_path(a, b), encode_exr(encode_motion_channels(m)))
        ctx.sink.write_file(sequence_flow_path(a, b), encode_flo(m.flow))
    elif kind == "tracks":
        vs = [ctx.views[n] for n in b]
        ctx.sink.write_file(tracks_path(a), encode_tracks(stream_tracks(ctx.st, vs, a, ctx.spec.sequence.tracks)))
    elif kind == "stereo_motion":
        fa, fb = tuple(ctx.views[n] for n in a), tuple(ctx.views[n] for n in b)
        for i, j in ((fa, fb), (fb, fa)):
            m = encode_stereo_motion_channels(ctx.stereo.motion(i, j))
            ctx.sink.write_file(stereo_motion_path(i[0].name, j[0].name), encode_exr(m))
    else:
        raise ValueError(f"unknown sequence item {item!r}")


def write_objects_document(spec, writer) -> str:
    """sequence/objects.json: every object's pose, presence and velocities per frame (the driver
    writes it before the items; no casting)."""
    timeline = Timeline(spec)
    frames = [(k, t, {o.name: (o.object_id, s) for o, s in zip(spec.objects, timeline.states(t).values())})
              for k, t in enumerate(spec.sequence.timestamps_s)]
    writer.write_file(SEQUENCE_OBJECTS, encode_json(objects_document(frames)))
    return SEQUENCE_OBJECTS


def finish_sequence(plan: SequencePlan, files, writer) -> dict:
    """Write the index (every view complete) with the ``files`` the stage wrote; returns it."""
    index = {**plan.index, "files": sorted(files)}
    if plan.whole:
        writer.write_file(SEQUENCE_INDEX, encode_json(index))
    return index
