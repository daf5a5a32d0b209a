"""A preview of each camera stream of a sequence with its point tracks drawn: ``<stream>.gif``
(Pillow) and ``<stream>.mp4`` (OpenCV, MPEG-4 part 2 ``mp4v``), at the clock's frame rate (or 10
frames / s for explicit timestamps).

Drawn on every frame: each track's point where it is visible, as a filled dot with its last
five visible positions as a trail, and as a small hollow ring where it is occluded but inside the
image (TAP-Vid's occluded flag; out-of-frame points are not drawn). Colours are fixed per track
(its index), so the same inputs give the same pictures.
"""
from __future__ import annotations

import io
import itertools

import cv2
import numpy as np
from PIL import Image

from scenegen.export.common import name, write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8

TRAIL_FRAMES = 5
_SHIFT = 4  # cv2 sub-pixel drawing: coordinates in 1/16 px


def _colour(n: int) -> tuple[int, int, int]:
    hsv = np.uint8([[[(n * 37) % 180, 220, 255]]])
    return tuple(int(c) for c in cv2.cvtColor(hsv, cv2.COLOR_HSV2RGB)[0, 0])


def draw_tracks(frames_rgb: np.ndarray, tracks) -> np.ndarray:
    """(T, H, W, 3) uint8 frames with the tracks (:class:`scenegen.dataset.codecs.TrackSet`) drawn."""
    out = frames_rgb.copy()
    xy = np.rint(np.nan_to_num(tracks.tracks_xy.astype(np.float64), nan=-1e6) * (1 << _SHIFT)).astype(np.int64)
    inside = ~tracks.out_of_frame
    for t in range(len(out)):
        img = np.ascontiguousarray(out[t])
        for n in range(len(xy)):
            colour = _colour(n)
            if tracks.occluded[n, t]:
                if inside[n, t]:
                    cv2.circle(img, tuple(int(c) for c in xy[n, t]), 3 << _SHIFT, colour, 1, cv2.LINE_AA, _SHIFT)
                continue
            seen = [k for k in range(max(0, t - TRAIL_FRAMES), t + 1) if not tracks.occluded[n, k]]
            for a, b in itertools.pairwise(seen):
                cv2.line(img, tuple(int(c) for c in xy[n, a]), tuple(int(c) for c in xy[n, b]), colour, 1,
                         cv2.LINE_AA, _SHIFT)
            cv2.circle(img, tuple(int(c) for c in xy[n, t]), 2 << _SHIFT, colour, -1, cv2.LINE_AA, _SHIFT)
        out[t] = img
    return out


def export(ds, dest, progress=None) -> dict:
    index = ds.sequence.index
    if index is None or not index.streams:
        raise ExportError(f"{ds.root} has no point tracks to preview (a sequence with 'sequence.tracks')")
    fps = (ds.spec or {}).get("sequence", {}).get("fps") or 10.0
    for k, (stream, frames) in enumerate(index.streams.items(), 1):
        video = np.stack([to_uint8(ds.image(v)) for v in frames])
        if video.ndim == 3:
            video = np.repeat(video[..., None], 3, axis=-1)
        drawn = draw_tracks(video, ds.sequence.tracks(stream))
        gif = io.BytesIO()
        pics = [Image.fromarray(f) for f in drawn]
        pics[0].save(gif, format="GIF", save_all=True, append_images=pics[1:], duration=round(1000 / fps),
                     loop=0)
        key = name("stream", stream)
        write(dest, f"{key}.gif", gif.getvalue())
        tmp = dest / f".{key}.partial.mp4"  # OpenCV writes to a path; moved into place whole
        h, w = drawn.shape[1:3]
        vw = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*"mp4v"), float(fps), (w, h))
        if not vw.isOpened():
            raise ExportError(f"{tmp}: OpenCV cannot write MPEG-4 video here")
        for f in drawn:
            vw.write(cv2.cvtColor(f, cv2.COLOR_RGB2BGR))
        vw.release()
        write(dest, f"{key}.mp4", tmp.read_bytes())
        tmp.unlink()
        if progress is not None:
            progress(k, len(index.streams))
    return {"files": 2 * len(index.streams), "streams": sorted(index.streams)}
