"""OpenEXR depth and disparity maps, through :func:`scenegen.dataset.codecs.read_exr` (OpenEXR bindings).

A map is one channel of the file. With ``channel=None`` the reader picks, in order: the only
channel; else the first present of :data:`DEPTH_CHANNELS` (``kind="depth"``) or
:data:`DISPARITY_CHANNELS` (``kind="disparity"``); else it raises naming the channels it found.
Our truth files (``truth/<view>.exr``) hold ``depth_z`` and are read that way. Non-finite values
(+inf marks a miss in our truth, and "unknown" in many tools) become NaN, recon_eval's missing
marker. HALF channels are read too (converted to float64; their precision is the writer's
choice).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.native import read_exr
from scenegen.dataset.codecs import write_exr

DEPTH_CHANNELS = ("depth_z", "depth", "Z", "Y", "R")
DISPARITY_CHANNELS = ("disparity", "disp", "Y", "R")


def read_exr_map(path, channel: str | None = None, *, kind: str = "depth") -> np.ndarray:
    """(H, W) float64 map from an EXR file, NaN where the stored value is not finite."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected an OpenEXR {kind} map)")
    try:
        ch = read_exr(p)
    except ValueError as exc:
        raise InputError(str(exc)) from None
    if channel is None:
        prefs = DEPTH_CHANNELS if kind == "depth" else DISPARITY_CHANNELS
        if len(ch) == 1:
            channel = next(iter(ch))
        else:
            channel = next((c for c in prefs if c in ch), None)
            if channel is None:
                raise InputError(f"{p}: cannot tell which channel holds the {kind} (channels {sorted(ch)};"
                                 f" expected one of {list(prefs)})")
    elif channel not in ch:
        raise InputError(f"{p}: no channel {channel!r} (channels {sorted(ch)})")
    a = np.asarray(ch[channel])
    if not np.issubdtype(a.dtype, np.floating):
        raise InputError(f"{p}: channel {channel!r} is {a.dtype}, expected a float {kind} channel")
    a = a.astype(np.float64)
    a[~np.isfinite(a)] = np.nan
    return a


def write_exr_map(path, image, channel: str = "depth_z") -> None:
    """Write an (H, W) map as one float32 channel (NaN written as +inf, a miss). For tests."""
    a = np.asarray(image, dtype=np.float64)
    if a.ndim != 2:
        raise InputError(f"write_exr_map: expected (H, W), got {a.shape}")
    write_exr(path, {channel: np.where(np.isnan(a), np.inf, a).astype(np.float32)})
