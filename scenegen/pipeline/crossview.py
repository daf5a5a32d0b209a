"""The cross-view stage of the pipeline: runs after every view is rendered, writes the cross-view
truth (docs/crossview.md) through the dataset writer (atomic, hashed in the manifest).

Only views that are complete in the dataset take part (a ``--frames`` run covers the pairs it
has). Each view's truth points are recomputed in float64 by the truth pass (one ray cast per
pixel, milliseconds; the same call as the stored truth), so resumed runs give the same bytes.
Views are projected into each other with their mid-exposure poses (the scene is at
mid-exposure, as for the truth; a sequence's objects at the views' time, which validation makes
the same for both views of a pair when objects move): for a moving camera with a rolling shutter, i's points follow
its per-row poses but j is projected as a global shutter at its mid-exposure pose.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.crossview.correspondence import flow_field
from scenegen.crossview.frames import FrameGeometry
from scenegen.crossview.motion import frame_motion
from scenegen.crossview.matches import MatchParams, label_real_matches, sift_matches, synthetic_matches
from scenegen.crossview.targets import board_view_truth
from scenegen.dataset.codecs import encode_exr, encode_flo, encode_json, encode_npy, read_png
from scenegen.dataset.crossview import (
    INDEX_FORMAT,
    INDEX_FORMAT_VERSION,
    INLIER,
    LABELS,
    MATCH_COLUMNS,
    OCCLUSION_REL_TOL,
    STATE_NAMES,
    TWOVIEW_PIXELS,
    VISIBLE,
    Correspondence,
    encode_correspondence_channels,
)
from scenegen.dataset.layout import (
    CROSSVIEW_INDEX,
    correspondence_path,
    flow_path,
    matches_path,
    twoview_path,
    view_paths,
    view_targets_path,
)
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.seeds import hashed_seed32
from scenegen.geometry.twoview import TwoView, plane_homography, plane_in_camera
from scenegen.pipeline.pairs import select_pairs, stereo_frames, streams
from scenegen.pipeline.stereo import write_stereo_frame
from scenegen.pipeline.view import correspond_fn, rolling_rows, view_time, view_truth, visibility_fn, visible_at

#: Spec geometry kinds that are planes in their object's z = 0 plane (normal +z): they get a
#: homography per pair.
PLANAR_KINDS = ("plane", "checkerboard", "charuco", "aruco_grid")


@dataclass(frozen=True)
class CrossviewSummary:
    pairs: int
    flows: int
    stereo_frames: int
    files: int


class CrossviewContext:
    """What the stage's items share where they run (the driver, or a Dask worker): the complete
    views, the loaded scene, the render settings, cached truth points and correspondences, and
    ``sink`` (``root``, ``write_file(rel, data)``) that writes the files."""

    def __init__(self, spec, views, built, sink, *, spp: int, seed: int):
        self.spec, self.built, self.sink = spec, built, sink
        self.spp, self.seed = spp, seed
        self.views = {v.name: v for v in views}
        self._points: dict = {}
        self._ids: dict = {}
        self._corr: dict = {}
        self._geometry: dict = {}

    def camera(self, name):
        v = self.views[name]
        return self.built.cameras[v.camera], v.cam_from_world

    def points(self, name) -> np.ndarray:
        """(H, W, 3) float64 world truth points of a view (NaN = no surface)."""
        if name not in self._points:
            t = view_truth(self.built, self.views[name], as_stored=True)  # the call (and kernel) of the stored truth
            self._points[name] = np.where(t[TruthKind.VALID][..., None], t[TruthKind.POINTS_WORLD], np.nan)
            self._ids[name] = t[TruthKind.OBJECT_ID].copy()
        return self._points[name]

    def geometry(self, name) -> FrameGeometry:
        """View ``name`` as a frame: its objects' poses, camera and, through a rolling shutter
        where something moves within the frame, its rows (:mod:`scenegen.crossview.frames`)."""
        if name not in self._geometry:
            v = self.views[name]
            rows = rolling_rows(self.built, v)
            poses = {o.object_id: (self.object_pose(o, name), True) for o in self.spec.objects}
            self._geometry[name] = FrameGeometry(poses, self.built.cameras[v.camera], v.cam_from_world,
                                                 visibility_fn(self.built, v, rows), rows, correspond_fn(self.built, v))
        return self._geometry[name]

    def time_s(self, name) -> float | None:
        """The clock time of view ``name`` (None: a static spec's view)."""
        return view_time(self.views[name])

    def object_pose(self, obj, name):
        """world_from_object of a spec object when view ``name`` was taken."""
        tl, t = self.built.timeline, getattr(self.views[name], "time_s", None)
        if tl is None or t is None or obj.name not in tl.animated:
            return obj.transform.world_from_object
        return tl.states(t)[obj.name].world_from_object

    def corr(self, i, j) -> Correspondence:
        if (i, j) not in self._corr:
            points = self.points(i)
            gi, gj = self.geometry(i), self.geometry(j)
            if gi.rolling is None and gj.rolling is None:  # in j's scene (the same time as i's: validated)
                self._corr[(i, j)] = gj.correspond(points)
            else:  # i's points at their rows' times, imaged by j's rows
                self._corr[(i, j)] = frame_motion(points, self._ids[i], gi, gj).correspondence
        return self._corr[(i, j)]

    def write(self, rel: str, data: bytes) -> None:
        self.sink.write_file(rel, data)


def _homographies(ctx: CrossviewContext, i: str, j: str) -> dict:
    """Plane homographies (undistorted pixels i -> j) of every planar object: planes and boards."""
    cam_i, pose_i = ctx.camera(i)
    cam_j, pose_j = ctx.camera(j)
    rel = pose_j @ pose_i.inverse()
    out = {}
    for obj in ctx.spec.objects:
        if obj.geometry.kind not in PLANAR_KINDS:
            continue
        wfo = ctx.object_pose(obj, i)
        n_i, d_i = plane_in_camera(pose_i, wfo.R[:, 2], wfo.t)  # object z = 0 plane, normal +z
        if abs(d_i) < 1e-12:
            continue  # camera i lies in the plane: no homography
        H = plane_homography(cam_i.K, cam_j.K, rel, n_i, d_i)
        out[obj.name] = {"H": H.tolist(), "plane_normal_i": n_i.tolist(), "plane_distance_i_m": d_i}
    return out


def _pair(ctx: CrossviewContext, cfg, a: str, b: str) -> dict:
    """Correspondences both ways, two-view geometry and match sets of one pair; its index entry."""
    entry = {"i": a, "j": b}
    for i, j in ((a, b), (b, a)):
        ctx.write(correspondence_path(i, j), encode_exr(encode_correspondence_channels(ctx.corr(i, j))))
    cam_a, pose_a = ctx.camera(a)
    cam_b, pose_b = ctx.camera(b)
    tv = TwoView.of(cam_a, pose_a, cam_b, pose_b).to_dict()
    tv.update({"i": a, "j": b, "homographies": _homographies(ctx, a, b), "pixels": TWOVIEW_PIXELS})
    ctx.write(twoview_path(a, b), encode_json(tv))
    if cfg.matches is not None:
        ms = cfg.matches
        p = MatchParams(count=ms.count, sigma_px=ms.sigma_px, outlier_fraction=ms.outlier_fraction,
                        near_miss_fraction=ms.near_miss_fraction, near_miss_px=tuple(ms.near_miss_px),
                        seed=hashed_seed32(ms.seed, a, b))
        c = ctx.corr(a, b)
        rows = synthetic_matches(c.uv, c.visible, cam_b.width, cam_b.height, p)
        ctx.write(matches_path(a, b, "synthetic"), encode_npy(rows))
        entry["synthetic_matches"] = {"count": len(rows), "seed": p.seed}
    if cfg.sift:
        root = ctx.sink.root
        pi, pj = sift_matches(read_png(root / view_paths(a)["image"]), read_png(root / view_paths(b)["image"]),
                              cfg.sift_ratio)
        ga, gb = ctx.geometry(a), ctx.geometry(b)
        if ga.rolling is None and gb.rolling is None:
            P = ctx.built.surface_points(cam_a, pose_a, pi, time_s=ctx.time_s(a))
            c = gb.correspond(P.reshape(-1, 1, 3))
        else:  # each keypoint's surface point at its row's time, imaged by b's rows
            rows = ga.rolling
            P, ids = ctx.built.surface_hits(cam_a, pose_a, pi, rows=None if rows is None else rows.cam,
                                              moves=rows.object_moves(pi[:, 1]) if rows and rows.objects else None,
                                              time_s=ctx.time_s(a))
            ids = np.zeros(len(pi), np.uint32) if ids is None else ids
            c = frame_motion(P.reshape(-1, 1, 3), ids.reshape(-1, 1), ga, gb, rows_a=pi[:, 1]).correspondence
        rows = label_real_matches(pi, pj, c.uv.reshape(-1, 2), c.state.ravel() == VISIBLE, cfg.sift_inlier_px)
        ctx.write(matches_path(a, b, "sift"), encode_npy(rows))
        inliers = int((rows[:, MATCH_COLUMNS.index("label")] == INLIER).sum())
        entry["sift_matches"] = {"count": len(rows), "inliers": inliers, "ratio": cfg.sift_ratio,
                                 "inlier_px": cfg.sift_inlier_px}
    return entry


@dataclass(frozen=True)
class CrossviewPlan:
    """The stage's items, in the order their index entries are listed: ``("pair", a, b)``,
    ``("flow", i, j)``, ``("stereo", left, right)``, ``("targets", view, None)``; ``done``: the
    complete views; ``whole``: every view is complete (the index is written)."""

    items: tuple[tuple, ...]
    done: tuple[str, ...]
    whole: bool


def plan_crossview(spec, views, is_complete, has_boards: bool) -> CrossviewPlan | None:
    """The items of the cross-view truth ``spec.crossview`` asks for (None when it is None), for
    the views ``is_complete(name)`` says are written (a ``--frames`` run covers what it has);
    ``has_boards``: the scene has calibration boards (per-view board truth)."""
    cfg = getattr(spec, "crossview", None)
    if cfg is None:
        return None
    done = [v for v in views if is_complete(v.name)]
    names = {v.name for v in done}
    items = [("pair", a, b) for a, b in select_pairs(cfg.pairs, views) if a in names and b in names]
    if cfg.flow:  # adjacent frames of the full stream, both complete: stable across --frames runs
        items += [("flow", va.name, vb.name) for vs in streams(views).values() for va, vb in zip(vs, vs[1:])
                  if va.name in names and vb.name in names]
    if cfg.stereo:
        items += [("stereo", left, right) for left, right in stereo_frames(done, spec.rigs)]
    if cfg.targets and has_boards:
        items += [("targets", v.name, None) for v in done]
    return CrossviewPlan(tuple(items), tuple(v.name for v in done), len(done) == len(views))


def execute_crossview_item(ctx: CrossviewContext, item: tuple):
    """Write one item's files through ``ctx``; returns its index entry."""
    kind, a, b = item
    if kind == "pair":
        return _pair(ctx, ctx.spec.crossview, a, b)
    if kind == "flow":
        for i, j in ((a, b), (b, a)):
            ctx.write(flow_path(i, j), encode_flo(flow_field(ctx.corr(i, j))))
        return {"i": a, "j": b}
    if kind == "stereo":
        return write_stereo_frame(ctx, a, b, spp=ctx.spp, seed=ctx.seed)
    if kind == "targets":
        return _board_views(ctx, a)
    raise ValueError(f"unknown cross-view item {item!r}")


def _board_views(ctx: CrossviewContext, name: str) -> str:
    """Every calibration board's truth in one view (a moving board moved with its object)."""
    cam, pose = ctx.camera(name)
    visible = visible_at(ctx.built, ctx.time_s(name))
    objects = {o.name: o for o in ctx.spec.objects}
    boards = {}
    for bname, (board, wfb) in ctx.built.boards.items():
        obj = objects[bname]
        wfb_v = ctx.object_pose(obj, name) @ obj.transform.world_from_object.inverse() @ wfb
        boards[bname] = board_view_truth(board, wfb_v, cam, pose, visible, ctx.geometry(name),
                                         (obj.object_id, ctx.object_pose(obj, name)))
    ctx.write(view_targets_path(name), encode_json({"view": name, "boards": boards}))
    return name


_INDEX_KEYS = {"pair": "pairs", "flow": "flow", "stereo": "stereo", "targets": "targets"}


def finish_crossview(plan: CrossviewPlan, entries, files, writer) -> CrossviewSummary:
    """Write the index (every view complete) of the items' ``entries`` (in the plan's order) and
    the ``files`` they wrote."""
    index = {"format": INDEX_FORMAT, "format_version": INDEX_FORMAT_VERSION,
             "occlusion_rel_tol": OCCLUSION_REL_TOL,
             "state_codes": {str(k): v for k, v in STATE_NAMES.items()},
             "match_columns": list(MATCH_COLUMNS), "match_labels": {str(k): v for k, v in LABELS.items()},
             "pairs": [], "flow": [], "stereo": [], "targets": []}
    for (kind, _, _), entry in zip(plan.items, entries):
        index[_INDEX_KEYS[kind]].append(entry)
    index["files"] = sorted(files)
    if plan.whole:  # the index describes the whole run; partial runs write none
        writer.write_file(CROSSVIEW_INDEX, encode_json(index))
    return CrossviewSummary(len(index["pairs"]), len(index["flow"]), len(index["stereo"]), len(files) + 1)
