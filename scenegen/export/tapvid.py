"""TAP-Vid point tracks: one pickle-free NPZ per camera stream of a sequence, ``<stream>.npz``,
with the arrays of a TAP-Vid video record (Doersch et al., "TAP-Vid: A Benchmark for Tracking
Any Point in a Video", NeurIPS 2022; the per-video dicts of its DAVIS/Kinetics pickles):

* ``video`` (T, H, W, 3) uint8: the stream's rendered frames (16-bit images rounded to 8 bit by
  :func:`scenegen.geometry.color.to_uint8`);
* ``points`` (N, T, 2) float32: ``[x, y]`` normalised to the image, TAP-Vid's raw form:
  ``((x + 0.5) / W, (y + 0.5) / H)`` of our pixel coordinates
  (:func:`scenegen.geometry.conventions.normalised_from_opencv_pixels`; ours put the top-left pixel's
  centre at (0, 0); TAP-Vid's normalised coordinates put the image's top-left corner at (0, 0)
  and its bottom-right corner at (1, 1));
* ``occluded`` (N, T) bool: TAP-Vid's occlusion flag (out of frame counts as occluded);
* ``query_points`` (N, 3) float32: ``[t, y, x]``, x and y normalised as ``points``.

The dataset's own tracks (sequence/tracks/, :mod:`scenegen.dataset.codecs.tracks`) keep pixel
coordinates and the out-of-frame flag.
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset.codecs import encode_npz
from scenegen.export.common import name, write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8
from scenegen.geometry.conventions import normalised_from_opencv_pixels


def export(ds, dest, progress=None) -> dict:
    index = ds.sequence.index
    if index is None or not index.streams:
        raise ExportError(f"{ds.root} has no point tracks (a sequence with 'sequence.tracks' writes them)")
    for k, (stream, frames) in enumerate(index.streams.items(), 1):
        tr = ds.sequence.tracks(stream)
        w, h = (float(x) for x in tr.image_size)
        points = normalised_from_opencv_pixels(tr.tracks_xy.astype(np.float64), (w, h)).astype(np.float32)
        q = tr.query_points.astype(np.float64)
        q_xy = normalised_from_opencv_pixels(q[:, [2, 1]], (w, h))
        query = np.column_stack([q[:, 0], q_xy[:, 1], q_xy[:, 0]]).astype(np.float32)
        video = np.stack([to_uint8(ds.image(v)) for v in frames])
        if video.ndim == 3:  # grey images: three equal channels, as TAP-Vid's videos are RGB
            video = np.repeat(video[..., None], 3, axis=-1)
        write(dest, f"{name('stream', stream)}.npz",
              encode_npz({"video": video, "points": points, "occluded": tr.occluded, "query_points": query}))
        if progress is not None:
            progress(k, len(index.streams))
    return {"files": len(index.streams), "streams": sorted(index.streams)}
