"""One view of a run: render it, cast its truth, run the camera's imaging chain.

The same function serves the serial run (:mod:`.run`), the Dask workers (:mod:`.distributed`) and
the cross-view stage (which recasts truth points with :func:`view_truth`), so a view's bytes do
not depend on where it was made.
"""
from __future__ import annotations

import pickle
from collections import OrderedDict

import numpy as np

from scenegen.crossview.correspondence import correspond
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.color import srgb_image
from scenegen.geometry.optics import PathMotion, cam_from_world_at, motion_to_dict
from scenegen.geometry.rolling import RollingRows, RowClock, RowPoses, frame_node_rows
from scenegen.geometry.seeds import hashed_seed32
from scenegen.dataset.codecs import encode_json
from scenegen.dataset.codecs.exr import encode_exr
from scenegen.dataset.layout import COC_CHANNEL, albedo_path, coc_path, lights_path
from scenegen.dataset.photometric import encode_albedo
from scenegen.imaging.stage import apply_imaging
from scenegen.pipeline.structured_light import lit_view, pattern_files, render_patterns
from scenegen.pipeline.view_boxes import view_boxes_file
from scenegen.spec.light_truth import view_lights_document
from scenegen.spec.timeline import poses_within_frame


#: Rolling-shutter row tables kept (the render, the truth and the cross-view and sequence stages
#: of a view ask for them in turn), keyed by what they are made of (:func:`_rows_key`).
ROWS_KEPT = 64
_ROWS: OrderedDict = OrderedDict()


def view_seed(seed: int, view_index: int) -> int:
    """Sampler seed of one view: distinct per view, fixed by (seed, index in the run) (uint32)."""
    return hashed_seed32(seed, view_index)


def rolling_shutter_rows(built, view):
    """Per-row ``cam_from_world`` for a moving camera with a rolling shutter, else None (made
    once per view)."""
    return _rows(built, view)[0]


def rolling_rows(built, view) -> RollingRows | None:
    """The camera's and the moving objects' poses at every row node of a rolling-shutter view in
    which something moves within the frame (:mod:`scenegen.geometry.rolling`), else None (made
    once per view)."""
    return _rows(built, view)[1]


def view_time(view) -> float | None:
    """The clock time of a view: a sequence's frame time, None for a static spec's view."""
    return getattr(view, "time_s", None)


def _rows_key(built, view) -> tuple:
    """What a view's row table is made of: the scene (its content hash: cameras, shutters and
    timeline), the camera, its pose and motion, and the time; not the view's name."""
    pose = view.cam_from_world.matrix.tobytes()
    return (built.description.content_hash, view.camera, pose, pickle.dumps(view.motion), view_time(view))


def _rows(built, view):
    """(per-row cam_from_world or None, RollingRows or None) of a view, cached by content: the
    truth pass's row poses are the table's nodes 0 .. H-1 themselves."""
    shutter = getattr(built.optics.get(view.camera), "shutter", None)
    camera_moves = view.motion is not None and not view.motion.is_static
    if shutter is None or shutter.rolling_readout_s == 0 or not (camera_moves or built.movers):
        return None, None  # a global shutter, or nothing moves: nothing to tabulate (or keep)
    key = _rows_key(built, view)
    cache = _ROWS
    if key in cache:
        cache.move_to_end(key)
    else:
        H = built.cameras[view.camera].height
        time_s = view_time(view)
        knots = [view.motion.knot_taus_s] if isinstance(view.motion, PathMotion) else []
        if built.movers and time_s is not None:
            knots.append(built.timeline.knot_times_s() - time_s)
        nodes = frame_node_rows(shutter, H, np.concatenate(knots) if knots else ())
        taus = shutter.row_time_s(nodes, H)
        clock = RowClock(shutter, H, 0.0 if time_s is None else float(time_s))  # the rows' times
        pixel = np.searchsorted(nodes, np.arange(H, dtype=np.float64))
        cam = [cam_from_world_at(view.cam_from_world, view.motion, float(tau)) for tau in taus]
        poses = [cam[k] for k in pixel] if camera_moves else None
        world_from_cam = [p.inverse() for p in cam]
        objects, present = {}, {}
        if built.movers:
            for oid, (R, t, p) in poses_within_frame(built.timeline, time_s, taus).items():
                objects[oid], present[oid] = RowPoses(R, t, node_rows=nodes, clock=clock), p
        rows = RollingRows(RowPoses(np.stack([p.R for p in world_from_cam]), np.stack([p.t for p in world_from_cam]),
                                    node_rows=nodes, clock=clock), objects, present, clock)
        cache[key] = (poses, rows)
        while len(cache) > ROWS_KEPT:  # bounded: a long run renders each view once
            cache.popitem(last=False)
    return cache[key]


def visibility_fn(built, view, rows: RollingRows | None):
    """The visibility cast of a frame (:class:`scenegen.crossview.frames.FrameGeometry`): in the
    scene at the view's time; with a rolling shutter's ``rows``, from each point's row centre
    with the moving objects where they are at that row's time (each ray cast at its own time)."""
    time_s = view_time(view)

    def visible(centres, points, point_rows=None):
        moves = (rows.object_moves_at_times(rows.clock.times_s(point_rows))
                 if rows is not None and rows.objects else None)
        return built.visible_from(centres, points, moves=moves, time_s=time_s)
    return visible


def visible_at(built, time_s: float | None):
    """``visible(centres, points)``: the visibility cast in the scene at ``time_s``."""
    return lambda centres, points: built.visible_from(centres, points, time_s=time_s)


def correspond_points(built, points_world, camera, cam_from_world, time_s: float | None = None):
    """Correspondences of world points (H, W, 3) in a view of the scene at ``time_s``: in one
    kernel where it applies (:meth:`scenegen.render.caster.Caster.correspond`), else
    :func:`scenegen.crossview.correspondence.correspond` with the visibility cast."""
    if built.kernel_correspondences:
        return built.correspond(points_world, camera, cam_from_world, time_s=time_s)
    return correspond(points_world, camera, cam_from_world, visible_at(built, time_s))


def correspond_fn(built, view):
    """A frame's correspondences of world points at the view's time (global shutter)."""
    time_s = view_time(view)

    def corr(points, camera, cam_from_world):
        return correspond_points(built, points, camera, cam_from_world, time_s)
    return corr


def view_truth(built, view, as_stored: bool = False) -> dict[str, np.ndarray]:
    """The truth pass of a view: per-row poses for a rolling shutter (the camera's, and the moving
    objects' where each row's rays meet them at the row's time); range and depth_z in float64,
    or as the dataset stores them (float32, rounded in the kernel) with ``as_stored``. A
    sequence's frame is cast at its time (the scene's objects there)."""
    rows = rolling_rows(built, view) if built.movers else None
    moves = rows.object_moves() if rows is not None and rows.objects else None
    return built.truth(built.cameras[view.camera], view.cam_from_world, row_poses=rolling_shutter_rows(built, view),
                       as_stored=as_stored, row_moves=moves, time_s=view_time(view))


def render_view_data(spec, built, index: int, v, *, spp: int, seed: int, all_patterns: bool = True):
    """One view's (image, linear_rgb, truth as stored, extra files or None), ready for
    :func:`scenegen.dataset.view_files.encode_view`; ``index`` is the view's position in the run.
    A projector-lit view is rendered under every pattern, or with ``all_patterns=False`` (a
    preview) under its first only, without its pattern files."""
    lit = lit_view(spec, v)  # a projector in the view's rig: one render per pattern, the first is the view's
    if lit is None:
        linear = built.render(v.camera, v.cam_from_world, spp=spp, seed=view_seed(seed, index), motion=v.motion,
                              light_scales=v.light_scales, time_s=view_time(v))  # a sequence's frame: at its time
    else:
        linears = render_patterns(built, v, lit, spp=spp, seed=view_seed(seed, index), time_s=view_time(v),
                                  count=None if all_patterns else 1)
        linear = linears[0]
    truth = view_truth(built, v, as_stored=True)
    params = spec.cameras[v.camera].imaging
    if params is None:  # clean path: sRGB encoding of the linear render
        image, extra = srgb_image(linear, spec.render.bit_depth), None
    else:  # the camera's photometric chain; its vignetting map is saved as truth, its raw
        # mosaic with imaging.raw
        image, extra = apply_imaging(linear, params, built.cameras[v.camera], spec.seed, index, v.name,
                                     camera_name=v.camera)
    if spec.truth is not None and (spec.truth.albedo or spec.truth.lights or spec.truth.defocus
                                   or spec.truth.boxes):
        extra = {**(extra or {}), **requested_truth_files(spec, built, v, truth)}
    if lit is not None and all_patterns:
        extra = {**(extra or {}), **pattern_files(spec, built, index, v, lit, linears, image, truth,
                                                  visible_at(built, view_time(v)))}
    return image, linear, truth, extra


def requested_truth_files(spec, built, view, truth) -> dict[str, bytes]:
    """The albedo map, the lights document, the circle of confusion and the boxes of a view, as the
    spec's ``truth:`` asks (docs/dataset_format.md, "Albedo and light truth", "Defocus truth");
    ``truth``: the view's truth as stored."""
    files = {}
    lens = getattr(built.optics.get(view.camera), "lens", None)
    if spec.truth.defocus and lens is not None:  # the thin lens's blur of each pixel's truth point
        coc = lens.blur_radius_px(built.cameras[view.camera], truth[TruthKind.DEPTH_Z].astype(np.float64))
        coc = np.where(truth[TruthKind.VALID], coc, np.nan).astype(np.float32)
        files[coc_path(view.name)] = encode_exr({COC_CHANNEL: coc})
    if spec.truth.albedo:
        if rolling_shutter_rows(built, view) is not None or (view.motion is not None and not view.motion.is_static) \
                or built.moving:
            raise ValueError(f"view {view.name!r}: albedo truth is for a still camera and a static scene "
                             "(no motion, no rolling shutter while moving)")
        files[albedo_path(view.name)] = encode_albedo(built.albedo(built.cameras[view.camera], view.cam_from_world,
                                                                   time_s=view_time(view)))
    if spec.truth.lights:
        files[lights_path(view.name)] = encode_json(view_lights_document(spec, view))
    if spec.truth.boxes:  # from the ids as stored and the meshes (docs/dataset_format.md, "Bounding boxes")
        rel, data = view_boxes_file(spec, built, view, truth)
        files[rel] = data
    return files


def view_optics(built, view) -> dict | None:
    """What cameras.json records of a view's lens and time effects (None if it has none)."""
    optics = built.optics.get(view.camera)
    d = optics.to_dict() if optics is not None else {}
    if isinstance(view.motion, PathMotion):  # a sequence's camera: its trajectory within the frame
        d["camera_motion"] = motion_to_dict(view.motion)
    elif view.motion is not None and not view.motion.is_static:
        d["camera_motion"] = {**motion_to_dict(view.motion), "frame": "camera (OpenCV axes), body velocities; "
                              "world_from_cam(tau) = world_from_cam @ [exp(w tau) | v tau], tau from mid-exposure"}
    ca = getattr(optics, "chromatic_aberration", None)
    if ca is not None:
        cams = ca.channel_cameras(built.cameras[view.camera])
        d["channel_cameras"] = {c: cam.to_dict() for c, cam in zip("RGB", cams)}
    return d or None
