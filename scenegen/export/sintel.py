"""MPI-Sintel layout from a sequence: one Sintel "scene" per camera stream (``<stream>``: the view
set's prefix, with ``_<member>`` for a rig member, as the point tracks), frames numbered from 1 as
Sintel does (``frame_0001`` is the stream's first frame):

* ``training/final/<stream>/frame_%04d.png``: the rendered image as delivered (lens, motion and
  sensor effects included: Sintel's "final" pass), 8-bit RGB;
* ``training/flow/<stream>/frame_%04d.flo``: forward flow to the next frame, the dataset's own
  Middlebury ``.flo`` byte for byte (unknown = 1e10 where the pixel saw nothing or its point does
  not project into the next frame); none for the last frame;
* ``training/occlusions/<stream>/frame_%04d.png``: 8-bit grey, 255 where the pixel's surface point
  is NOT seen in the next frame (occluded, out of frame, or its object gone: Sintel's "unmatched"
  pixels), 0 elsewhere;
* ``training/invalid/<stream>/frame_%04d.png``: 8-bit grey, 255 where the flow is unknown (no
  surface, or no projection into the next frame), 0 elsewhere (Sintel's readme: "invalid pixel
  maps"; our flow is exact everywhere else);
* ``training/depth/<stream>/frame_%04d.dpt``: z-depth along the optical axis (``depth_z``,
  metres), 0 where the pixel saw nothing (:mod:`scenegen.dataset.codecs.sintel`);
* ``training/camdata_left/<stream>/frame_%04d.cam``: M = K (3x3, with skew; our pixels: the
  top-left pixel's centre at (0, 0), which the SDK does not state either way), N = [R | t] of
  ``cam_from_world`` (OpenCV axes, metres), ``x = M N X`` (the SDK's ``cam_read``).

Sintel's cameras are pinholes: a stream of a distorted camera (``opencv``, ``fisheye``) is refused
(its flow and depth are on distorted pixels that M cannot describe), as is a moving camera with
a rolling shutter (its truth follows per-row poses; N holds one). ``streams.json`` lists each
stream's frames (our view names).
"""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.codecs import encode_cam, encode_dpt, encode_png
from scenegen.dataset.crossview import NO_SURFACE, VISIBLE
from scenegen.dataset.layout import sequence_flow_path
from scenegen.dataset.truth import TruthKind
from scenegen.export.common import name, write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8


def _streams(ds) -> dict[str, list[str]]:
    """Stream name -> its complete views in frame order."""
    out: dict[str, list] = {}
    for v in ds.views:
        info = ds.view_info(v)
        prefix = info.get("view_set") or info["camera_name"]
        key = name("stream", prefix if info.get("rig_member") is None else f"{prefix}_{info['rig_member']}")
        out.setdefault(key, []).append((info["frame_index"], v))
    return {k: [v for _, v in sorted(items)] for k, items in out.items()}


def _check_pinhole(ds, view: str) -> None:
    info = ds.view_info(view)
    cam, _ = ds.camera(view)
    if cam.model != "pinhole":
        raise ExportError(f"camera {info['camera_name']!r} (view {view}) is a {cam.model!r} camera: Sintel's "
                          "cameras are pinholes (x = M N X) and its flow and depth would be on distorted "
                          "pixels; render the sequence with a pinhole camera")
    optics = info.get("optics") or {}
    if (optics.get("shutter") or {}).get("rolling_readout_s", 0.0) and "camera_motion" in optics:
        raise ExportError(f"camera {info['camera_name']!r} (view {view}) moves with a rolling shutter: its "
                          "truth follows per-row poses that one Sintel .cam cannot hold")


def _mask8(mask) -> np.ndarray:
    """(H, W) uint8: 255 where ``mask``, 0 elsewhere (Sintel's occlusion and invalid maps)."""
    return np.where(mask, 255, 0).astype(np.uint8)


def _rgb8(image) -> np.ndarray:
    img = to_uint8(image)
    return np.repeat(img[..., None], 3, axis=-1) if img.ndim == 2 else img


def export(ds, dest, progress=None) -> dict:
    index = ds.sequence.index
    forward = {(a, b) for a, b, step in (index.pairs if index is not None else ()) if step == 1}
    if not forward:
        raise ExportError(f"{ds.root} has no sequence flow with step 1 (a sequence with flow_steps [1, ...])")
    streams = _streams(ds)
    for views in streams.values():
        _check_pinhole(ds, views[0])
    n, done, listing = 0, 0, {}
    for stream, views in streams.items():
        for k, v in enumerate(views):
            frame = f"{stream}/frame_{k + 1:04d}"
            cam, pose = ds.camera(v)
            truth = ds.truth(v)
            write(dest, f"training/final/{frame}.png", encode_png(_rgb8(ds.image(v))))
            depth = np.where(truth[TruthKind.VALID], truth[TruthKind.DEPTH_Z], 0.0)
            write(dest, f"training/depth/{frame}.dpt", encode_dpt(depth))
            write(dest, f"training/camdata_left/{frame}.cam",
                  encode_cam(cam.K, np.concatenate([pose.R, pose.t[:, None]], axis=1)))
            n += 3
            if k + 1 < len(views):
                b = views[k + 1]
                if (v, b) not in forward:
                    raise ExportError(f"{ds.root}: no sequence flow {v} -> {b} in the sequence index")
                flo = ds.read(sequence_flow_path(v, b), lambda p: p.read_bytes(), f"flow {v} -> {b}")
                write(dest, f"training/flow/{frame}.flo", flo)
                m = ds.sequence.motion(v, b)
                unmatched = (m.state != VISIBLE) & (m.state != NO_SURFACE)
                unknown = ~np.isfinite(m.flow[..., 0])
                write(dest, f"training/occlusions/{frame}.png", encode_png(_mask8(unmatched)))
                write(dest, f"training/invalid/{frame}.png", encode_png(_mask8(unknown)))
                n += 3
            done += 1
            if progress is not None:
                progress(done, len(ds.views))
        listing[stream] = views
    write(dest, "streams.json", (json.dumps({"streams": listing}, indent=1) + "\n").encode())
    return {"files": n + 1, "streams": sorted(streams)}
