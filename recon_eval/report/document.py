"""Result serialisation: versioned JSON (written atomically) and a terminal table.

JSON schema (``schema_version`` "1.0", documented in docs/metrics.md): an object with
``schema_version``, ``recon_eval_version``, ``command``, ``inputs`` (paths and options, i.e.
provenance) and ``results`` (metric name -> the result dataclass as an object; arrays as lists).
Non-finite numbers are written as the strings "inf", "-inf", "nan" (strict JSON has no literal).
"""
from __future__ import annotations

import dataclasses
import json
import math
from enum import Enum

import numpy as np

from recon_eval import SCHEMA_VERSION, __version__
from scenegen.dataset.files import atomic_write_bytes


def to_jsonable(obj):
    """Dataclasses, numpy arrays/scalars, enums, tuples -> plain JSON values."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, Enum):
        return obj.value
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer, int)):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        x = float(obj)
        if math.isfinite(x):
            return x
        return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    return obj


def document(command: str, inputs: dict, results: dict) -> dict:
    return {
        "schema_version": SCHEMA_VERSION,
        "recon_eval_version": __version__,
        "command": command,
        "inputs": to_jsonable(inputs),
        "results": to_jsonable(results),
    }


def write_json_atomic(path, doc: dict) -> None:
    """Write ``doc`` to ``path`` atomically (:func:`scenegen.dataset.files.atomic_write`: a temporary file in
    the same directory, fsync, os.replace), so a reader never sees a half-written file."""
    atomic_write_bytes(path, (json.dumps(doc, indent=2, allow_nan=False) + "\n").encode("utf-8"))


def scalar_rows(results: dict) -> list[tuple[str, str, str]]:
    """(metric, field, value) rows of the scalar fields of each result (arrays are left to JSON)."""
    rows = []
    for name, res in results.items():
        data = to_jsonable(res)
        flat = _flatten(data)
        for key, val in flat:
            rows.append((name, key, _fmt(val)))
    return rows


def _flatten(d, prefix=""):
    out = []
    if isinstance(d, dict):
        for k, v in d.items():
            out += _flatten(v, f"{prefix}{k}" if not prefix else f"{prefix}.{k}")
    elif isinstance(d, list):
        if len(d) <= 4 and all(not isinstance(v, (list, dict)) for v in d):
            out.append((prefix, d))
    else:
        out.append((prefix, d))
    return out


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, list):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)


def print_table(title: str, results: dict) -> None:
    from rich.console import Console  # heavy; only a printed table needs it
    from rich.table import Table  # (rich, as above)

    table = Table(title=title)
    for col in ("metric", "field", "value"):
        table.add_column(col)
    for row in scalar_rows(results):
        table.add_row(*row)
    Console().print(table)
