"""A user's normal map, light directions and intensities: the files photometric stereo methods
write (DiLiGenT's conventions: ``light_directions.txt`` and ``light_intensities.txt``, one image
per row).

Normal maps: ``.npy`` (H, W, 3) float; ``.exr`` with channels R, G, B or X, Y, Z (or N.X, N.Y,
N.Z); ``.png`` 8- or 16-bit RGB encoding n = 2 c / c_max - 1 (the normals-to-colour mapping
DiLiGenT's results and most methods write), decoded and normalised (the encoding is quantised);
an all-zero PNG pixel (DiLiGenT's ``.* mask`` background) decodes to 0, no normal. Float maps are
taken as they are (DiLiGenT's evaluation does not normalise).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.npy import read_npy
from recon_eval.readers.rows import read_rows
from scenegen.dataset.codecs import read_exr, read_png

NORMAL_MAP_SUFFIXES = (".npy", ".exr", ".png")
_EXR_NAMES = (("R", "G", "B"), ("X", "Y", "Z"), ("N.X", "N.Y", "N.Z"))


def read_normal_map(path) -> np.ndarray:
    """(H, W, 3) float64 normals of a ``.npy``, ``.exr`` or ``.png`` file (module docstring)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in NORMAL_MAP_SUFFIXES:
        raise InputError(f"{p}: expected a normal map {', '.join(NORMAL_MAP_SUFFIXES)}, got {suffix or 'no suffix'}")
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a normal map)")
    if suffix == ".npy":
        return read_npy(p, (None, None, 3))
    try:
        data = read_exr(p) if suffix == ".exr" else read_png(p)
    except (ValueError, KeyError, OSError) as exc:
        raise InputError(f"{p}: unreadable normal map ({exc})") from None
    if suffix == ".exr":
        names = next((n for n in _EXR_NAMES if all(c in data for c in n)), None)
        if names is None:
            raise InputError(f"{p}: expected channels R, G, B or X, Y, Z (or N.X, N.Y, N.Z), got {sorted(data)}")
        return np.stack([np.asarray(data[c], np.float64) for c in names], axis=-1)
    img = np.asarray(data)
    if img.ndim != 3 or img.shape[2] < 3:
        raise InputError(f"{p}: expected an RGB PNG (normals encoded as (n + 1) / 2), got shape {img.shape}")
    c = img[..., :3].astype(np.float64)
    n = 2.0 * c / float(np.iinfo(img.dtype).max) - 1.0
    norm = np.linalg.norm(n, axis=-1, keepdims=True)
    zero = (img[..., :3] == 0).all(axis=-1)
    return np.where(zero[..., None], 0.0, n / np.where(norm > 0, norm, 1.0))


def read_light_rows(path, n_rows: int, what: str) -> np.ndarray:
    """(n_rows, 3) float64 of a text file with one row of 3 numbers per image (DiLiGenT's
    ``light_directions.txt`` / ``light_intensities.txt``); a single column is repeated 3 times."""
    rows = read_rows(path, what, (1, 3))
    if len(rows) != n_rows:
        raise InputError(f"{path}: expected {n_rows} rows ({what}, one per image of the set), got {len(rows)}")
    return np.array([np.repeat(r.values, 3) if len(r.values) == 1 else r.values for r in rows], np.float64)
