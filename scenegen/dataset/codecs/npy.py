"""NPY: ``np.save``'s format, never pickles."""
from __future__ import annotations

import io

import numpy as np

from scenegen.dataset.files import atomic_write_bytes, read_decoded


def encode_npy(arr) -> bytes:
    """``np.save`` bytes of ``arr`` (object arrays are refused: no pickles)."""
    buf = io.BytesIO()
    np.save(buf, np.asarray(arr), allow_pickle=False)
    return buf.getvalue()


def write_npy(path, arr) -> None:
    """Write ``arr`` in NPY format (no pickles), atomically."""
    atomic_write_bytes(path, encode_npy(arr))


def read_npy(path) -> np.ndarray:
    """Read an NPY file (pickles refused); a ValueError names the file."""
    return read_decoded(path, decode_npy)


def decode_npy(data: bytes) -> np.ndarray:
    """Inverse of :func:`encode_npy` (pickles refused)."""
    return np.load(io.BytesIO(bytes(data)), allow_pickle=False)
