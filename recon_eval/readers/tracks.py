"""Predicted point tracks (TAP-Vid style) from a pickle-free ``.npz``: positions (N, T, 2) px
``[x, y]`` and occlusion (N, T) bool, one row per query of the truth's tracks file in its order.

Accepted keys, so common trackers' dumps load as they are: positions ``tracks_xy`` (scenegen's
own key) or ``tracks``; occlusion ``occluded`` (True = occluded), or ``visibles`` / ``visibility``
(True = visible; CoTracker, TAPIR outputs), negated. A file that needs pickle is refused.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from scenegen.dataset.codecs import decode_npz

POSITION_KEYS = ("tracks_xy", "tracks")
OCCLUDED_KEYS = ("occluded",)
VISIBLE_KEYS = ("visibles", "visibility")


def read_tracks(path, n_tracks: int, n_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """(tracks (N, T, 2) float64 px, occluded (N, T) bool) of the ``.npz`` at ``path``, checked
    against the truth's ``n_tracks`` x ``n_frames``."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a pickle-free .npz of tracks)")
    try:
        arrays = decode_npz(p.read_bytes())  # every declared array size checked before allocating
    except (OSError, ValueError) as e:
        raise InputError(f"{p}: not a readable pickle-free .npz of tracks ({e})") from None
    pos_key = next((k for k in POSITION_KEYS if k in arrays), None)
    if pos_key is None:
        raise InputError(f"{p}: no track positions (expected a key {' or '.join(POSITION_KEYS)}; "
                         f"found {', '.join(sorted(arrays)) or 'none'})")
    pos = np.asarray(arrays[pos_key])
    if pos.shape != (n_tracks, n_frames, 2) or not np.issubdtype(pos.dtype, np.number):
        raise InputError(f"{p}: {pos_key}: expected numbers of shape ({n_tracks}, {n_frames}, 2) "
                         f"(one row per truth query, x y per frame), got {pos.dtype} {pos.shape}")
    occ_key = next((k for k in OCCLUDED_KEYS + VISIBLE_KEYS if k in arrays), None)
    if occ_key is None:
        raise InputError(f"{p}: no occlusion (expected a key occluded, visibles or visibility)")
    occ = np.asarray(arrays[occ_key])
    if occ.shape != (n_tracks, n_frames) or not (occ.dtype == bool or np.all(np.isin(occ, (0, 1)))):
        raise InputError(f"{p}: {occ_key}: expected booleans of shape ({n_tracks}, {n_frames}), "
                         f"got {occ.dtype} {occ.shape}")
    occ = occ.astype(bool)
    return pos.astype(np.float64), occ if occ_key in OCCLUDED_KEYS else ~occ
