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
        raise InputError(f"{p}: not a readable .npy array ({str(exc).removeprefix(f'{p}: ')})") from None
    if not np.issubdtype(a.dtype, np.number) and a.dtype != bool:
        raise InputError(f"{p}: expected a numeric array, got dtype {a.dtype}")
    if shape is not None:
        ok = a.ndim == len(shape) and all(s is None or s == n for s, n in zip(shape, a.shape))
        if not ok:
            want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
            raise InputError(f"{p}: expected an array of shape {want}, got {a.shape}")
    return a.astype(np.float64)


def read_mask(path, n: int | None = None) -> np.ndarray:
    """(N,) bool mask from a ``.npy`` array (bool or 0/1 numbers, any shape with N elements) or a
    text file of 0/1 values; ``n``: the expected length (the rows it labels)."""
    p = Path(path)
    if p.suffix.lower() == ".npy":
        a = read_npy(p).reshape(-1)
    else:
        if not p.is_file():
            raise InputError(f"{p}: no such file (expected a mask: .npy or text of 0/1 values)")
        try:
            a = np.array([float(v) for v in p.read_text().replace(",", " ").split()])
        except (ValueError, UnicodeDecodeError):
            raise InputError(f"{p}: expected 0/1 values") from None
    if not np.all((a == 0) | (a == 1)):
        raise InputError(f"{p}: a mask holds 0/1 (or bool) values only")
    if n is not None and len(a) != n:
        raise InputError(f"{p}: {len(a)} mask values for {n} rows")
    return a.astype(bool)
