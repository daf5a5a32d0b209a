"""A 3x3 matrix (F, E, H, K) from .npy, .json (nested list, or {"F": ...}/{"H": ...}) or text
(9 numbers, whitespace or commas, '#' comments)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.npy import read_npy
from recon_eval.readers.text import json_document, read_text


def read_matrix3(path, key: str | None = None) -> np.ndarray:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a 3x3 matrix as .npy, .json or .txt)")
    if p.suffix.lower() == ".npy":
        return read_npy(p, (3, 3))
    text = read_text(p, "a 3x3 matrix as text or JSON")
    if p.suffix.lower() == ".json":
        obj = json_document(text, p, "a 3x3 matrix")
        if isinstance(obj, dict):
            if key is None or key not in obj:
                raise InputError(f"{p}: expected a 3x3 list or an object with key {key!r}")
            obj = obj[key]
        try:
            M = np.asarray(obj, dtype=np.float64)
        except (TypeError, ValueError):
            raise InputError(f"{p}: expected a 3x3 array of numbers") from None
    else:
        lines = [ln.split("#", 1)[0] for ln in text.splitlines()]
        try:
            M = np.array([float(v) for v in " ".join(lines).replace(",", " ").split()])
        except ValueError:
            raise InputError(f"{p}: expected 9 numbers") from None
    if M.size != 9:
        raise InputError(f"{p}: expected a 3x3 matrix (9 numbers), got {M.size}")
    return M.reshape(3, 3)
