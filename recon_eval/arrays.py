"""Input validation shared by the metric modules: shapes, dtypes, and frozen array fields."""
from __future__ import annotations

import numpy as np

from recon_eval.errors import InputError


def as_float_array(a, name: str, shape: tuple) -> np.ndarray:
    """``a`` as a float64 array whose shape matches ``shape`` (``None`` = any length).

    Raises :class:`InputError` naming ``name`` and the expected shape otherwise.
    """
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: expected a numeric array of shape {_fmt(shape)} ({exc})") from None
    ok = arr.ndim == len(shape) and all(s is None or s == n for s, n in zip(shape, arr.shape))
    if not ok:
        raise InputError(f"{name}: expected shape {_fmt(shape)}, got {arr.shape}")
    return arr


def frozen(a) -> np.ndarray:
    """A read-only float64 copy, for array fields of frozen result dataclasses."""
    arr = np.array(a, dtype=np.float64, copy=True)
    arr.setflags(write=False)
    return arr


def _fmt(shape: tuple) -> str:
    return "(" + ", ".join("N" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
