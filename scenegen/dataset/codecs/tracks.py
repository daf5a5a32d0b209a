"""Point tracks (TAP-Vid style) as a pickle-free NPZ: ``sequence/tracks/<stream>.npz``.

Keys (all arrays; no object arrays, so ``np.load(..., allow_pickle=False)`` reads it):

* ``query_points`` (N, 3) float32: ``[t, y, x]`` per track, as TAP-Vid: t the frame index in the
  stream, (x, y) the query pixel in the project's convention (pixel (0, 0) is the CENTRE of the
  top-left pixel, x right, y down; docs/conventions.md).
* ``tracks_xy`` (N, T, 2) float32: ``[x, y]`` of the track's surface point in every frame, same
  convention; the projection also where the point is occluded or out of frame (NaN only where
  it does not project: behind the camera or beyond its model's field of view).
* ``occluded`` (N, T) bool: not visible, by the ray cast of the frame's scene; out of frame
  counts as occluded (TAP-Vid), as does an object that has left the scene.
* ``out_of_frame`` (N, T) bool: the point projects outside the image (or not at all).
* ``image_size`` (2,) int32: ``[width, height]`` in pixels.
* ``frame_names`` (T,) unicode: the view names of the stream's frames, in order.

The archive is written with fixed member timestamps (numpy's ``savez`` stamps the current
time), so identical tracks give identical bytes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset.codecs.npy import decode_npz, encode_npz
from scenegen.dataset.files import atomic_write_bytes, read_decoded

TRACK_KEYS = ("query_points", "tracks_xy", "occluded", "out_of_frame", "image_size", "frame_names")


@dataclass(frozen=True, eq=False)
class TrackSet:
    """The tracks of one camera stream (see the module docstring for the arrays)."""

    query_points: np.ndarray  # (N, 3) float32 [t, y, x]
    tracks_xy: np.ndarray  # (N, T, 2) float32 [x, y]
    occluded: np.ndarray  # (N, T) bool
    out_of_frame: np.ndarray  # (N, T) bool
    image_size: np.ndarray  # (2,) int32 [width, height]
    frame_names: np.ndarray  # (T,) unicode

    def __post_init__(self):
        arrays = {
            "query_points": np.asarray(self.query_points, np.float32),
            "tracks_xy": np.asarray(self.tracks_xy, np.float32),
            "occluded": np.asarray(self.occluded, bool),
            "out_of_frame": np.asarray(self.out_of_frame, bool),
            "image_size": np.asarray(self.image_size, np.int32),
            "frame_names": np.asarray(self.frame_names, dtype=str),
        }
        n, t = arrays["occluded"].shape if arrays["occluded"].ndim == 2 else (-1, -1)
        shapes = {"query_points": (n, 3), "tracks_xy": (n, t, 2), "occluded": (n, t),
                  "out_of_frame": (n, t), "image_size": (2,), "frame_names": (t,)}
        for k, shape in shapes.items():
            if arrays[k].shape != shape or n < 0:
                raise ValueError(f"tracks: {k} must have shape {shape} (N tracks, T frames), got "
                                 f"{arrays[k].shape}")
        check_finite_where_visible(arrays["query_points"], arrays["tracks_xy"], arrays["occluded"])
        for k, v in arrays.items():
            object.__setattr__(self, k, v)

    def __len__(self) -> int:
        return len(self.query_points)


def check_finite_where_visible(query_points: np.ndarray, tracks_xy: np.ndarray, occluded: np.ndarray) -> None:
    """The rule every reader of tracks relies on (the exports, recon-eval's scoring): query points
    are finite and a point marked visible has a finite position; ValueError naming the first
    track and frame that breaks it. Written tracks always keep it (NaN only where a point does not
    project, which is out of frame, so occluded)."""
    bad_q = ~np.isfinite(query_points).all(axis=1)
    if bad_q.any():
        raise ValueError(f"tracks: query_points: track {int(np.argmax(bad_q))} is not finite "
                         f"({int(bad_q.sum())} such tracks)")
    bad = ~np.isfinite(tracks_xy).all(axis=2) & ~occluded
    if bad.any():
        n, t = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"tracks: tracks_xy: track {n} at frame {t} is visible (not occluded) but not "
                         f"finite ({int(bad.sum())} such points): expected finite pixel positions")


def encode_tracks(tracks: TrackSet) -> bytes:
    """NPZ bytes (:func:`encode_npz`) of the six arrays of :data:`TRACK_KEYS`."""
    return encode_npz({key: getattr(tracks, key) for key in TRACK_KEYS})


def decode_tracks(data: bytes) -> TrackSet:
    """Inverse of :func:`encode_tracks`; ValueError naming a missing key or a wrong shape (array
    sizes checked before anything is allocated: :func:`scenegen.dataset.codecs.npy.decode_npz`)."""
    try:
        arrays = decode_npz(data, required=TRACK_KEYS)
    except ValueError as e:
        raise ValueError(f"tracks: {e}") from None
    return TrackSet(**{k: arrays[k] for k in TRACK_KEYS})


def write_tracks(path, tracks: TrackSet) -> None:
    atomic_write_bytes(path, encode_tracks(tracks))


def read_tracks(path) -> TrackSet:
    """Read a tracks NPZ; a ValueError names the file."""
    return read_decoded(path, decode_tracks)
