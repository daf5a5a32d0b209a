"""JSON, canonical: UTF-8, sorted keys, indent 2, trailing newline; floats in Python's shortest
round-trip form (``repr``), so a float64 read back is bit-identical. NaN and infinities are
refused (they are not JSON). numpy scalars and arrays are converted to Python numbers and lists.
Identical inputs give identical bytes.
"""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from scenegen.dataset.files import atomic_write_bytes, read_decoded


def _json_default(o: Any):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.bool_):
        return bool(o)
    if isinstance(o, np.integer):
        return int(o)
    if isinstance(o, np.floating):
        return float(o)  # exact for float16/32/64; repr then round-trips the float64
    if isinstance(o, os.PathLike):
        return Path(o).as_posix()
    if isinstance(o, (set, frozenset)):
        raise TypeError("sets have no stable order; pass a sorted list")
    raise TypeError(f"object of type {type(o).__name__} is not JSON serialisable")


def encode_json(obj: Any) -> bytes:
    """Canonical JSON bytes: sorted keys, indent 2, ``repr`` floats, UTF-8, trailing newline.

    Raises ValueError for NaN/inf (not valid JSON) and TypeError for unsupported objects.
    """
    try:
        text = json.dumps(obj, sort_keys=True, indent=2, ensure_ascii=False, allow_nan=False,
                          default=_json_default)
    except ValueError as e:
        raise ValueError(f"cannot write JSON: {e} (NaN and infinities are not JSON)") from e
    return (text + "\n").encode("utf-8")


def write_json(path, obj: Any) -> None:
    """Write ``obj`` as canonical JSON (:func:`encode_json`), atomically."""
    atomic_write_bytes(path, encode_json(obj))


def read_json(path) -> Any:
    """Parse a JSON file; a ValueError names the file."""
    return read_decoded(path, decode_json)


def decode_json(data: bytes) -> Any:
    """Parse UTF-8 JSON bytes (ValueError for invalid JSON or text)."""
    try:
        return json.loads(data.decode("utf-8"))
    except RecursionError:  # a hostile file: arrays nested thousands deep
        raise ValueError("invalid JSON: nested too deeply") from None
