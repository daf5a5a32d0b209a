"""Plain NumPy ``.npy`` arrays (no pickles), through :func:`scenegen.dataset.codecs.read_npy`, with
the evaluator's expected-shape check and errors naming the file."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from scenegen.dataset.codecs import read_npy as decode_npy_file


def read_npy(path, shape: tuple | None = None) -> np.ndarray:
    """float64 array from ``path``; ``shape`` entries of None match any length."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a .npy array)")
    try:
        a = decode_npy_file(p)
    except (ValueError, OSError, EOFError) as exc:
        raise InputError(f"{p}: not a readable .npy array ({exc})") from None
    if not np.issubdtype(a.dtype, np.number) and a.dtype != bool:
        raise InputError(f"{p}: expected a numeric array, got dtype {a.dtype}")
    if shape is not None:
        ok = a.ndim == len(shape) and all(s is None or s == n for s, n in zip(shape, a.shape))
        if not ok:
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
            raise InputError(f"{p}: expected an array of shape {want}, got {a.shape}")
    return a.astype(np.float64)
