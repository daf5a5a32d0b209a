"""Text tables: one record per line, fields separated by whitespace or commas, ``#`` starts a
comment, blank and comment-only lines are skipped. Numbers are Python floats (``inf`` and ``nan``
included: a failed estimate is scored, not refused). Every problem names ``file:line``.

Used for the camera matrices, projective points and triangulated points of ``recon-eval dlt`` and
``recon-eval triangulation`` (docs/metrics.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.npy import read_npy
from recon_eval.readers.text import read_text


@dataclass(frozen=True)
class Row:
    line: int  # 1-based line number in the file
    labels: tuple  # the leading non-numeric fields (strings), ``n_labels`` of them
    values: np.ndarray  # (C,) float64, the numeric fields


def read_rows(path, what: str, n_values: tuple, n_labels: int = 0) -> list[Row]:
    """The records of the text table ``path``: each has ``n_labels`` leading string fields and then
    a number of numeric fields in ``n_values`` (e.g. ``(3,)`` or ``(3, 4)``). ``what`` says what a
    record is, for the error messages (e.g. ``"X Y Z"``)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected {what} rows as text)")
    rows = []
    for k, raw in enumerate(read_text(p, f"{what} rows").splitlines(), start=1):
        fields = raw.split("#", 1)[0].replace(",", " ").split()
        if not fields:
            continue
        n = len(fields) - n_labels
        if n not in n_values:
            want = " or ".join(str(v + n_labels) for v in n_values)
            raise InputError(f"{p}:{k}: expected {want} fields ({what}), got {len(fields)}")
        try:
            vals = np.array([float(f) for f in fields[n_labels:]], dtype=np.float64)
        except ValueError:
            bad = next(f for f in fields[n_labels:] if not _is_float(f))
            raise InputError(f"{p}:{k}: {bad!r} is not a number (expected {what})") from None
        rows.append(Row(k, tuple(fields[:n_labels]), vals))
    return rows


def _is_float(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def read_projection_matrix(path) -> np.ndarray:
    """A 3x4 camera matrix P (3, 4) float64 from ``.npy`` or text (3 rows of 4 numbers).
    Non-finite entries are kept (scored as a failed estimate)."""
    p = Path(path)
    if p.suffix.lower() == ".npy":
        return read_npy(p, (3, 4))
    rows = read_rows(p, "a row of the 3x4 camera matrix P", (4,))
    if len(rows) != 3:
        where = f"{p}:{rows[3].line}" if len(rows) > 3 else str(p)
        raise InputError(f"{where}: expected a 3x4 camera matrix (3 rows of 4 numbers), got {len(rows)} rows")
    return np.stack([r.values for r in rows])
