"""The rule behind every number of a parsed spec: finite, also where the parser derived it.

Each YAML number is checked as it is read (finite, in its field's range), but a derived value can
still overflow: ``fps: 1e-320`` is a positive number, and ``start_s + k / fps`` is infinite from
frame 1 on. Such a value used to reach the renderer and the dataset's JSON (``Out of range float
values are not JSON compliant``, naming nothing). :func:`check_finite` walks the whole parsed spec
(records, tuples, mappings, arrays, poses) once, after every value is computed, and names the
first value that is not finite at the spec line of its nearest record, with the field and how it
was derived (the field's ``derived`` metadata, docs/scene_spec.md).
"""
from __future__ import annotations

import dataclasses
import math
from types import MappingProxyType

import numpy as np

from scenegen.errors import SpecError, Where
from scenegen.geometry.pose import Rigid3
from scenegen.spec.model.meta import spec_meta

#: Fields that are no numbers of the scene: places, files, messages.
_SKIP = frozenset({"where", "path", "path_as_written", "file", "base_dir", "warnings", "files"})


def check_finite(spec) -> None:
    """SpecError at the nearest recorded spec line for the first non-finite number of ``spec``."""
    _walk(spec, "", getattr(spec, "where", None) or Where(file=getattr(spec, "file", None)), None)


def _fail(where: Where, path: str, value, derived: str | None) -> None:
    field = ".".join(p for p in (where.field, path.lstrip(".")) if p) or None
    how = f" (derived: {derived}: the numbers it is made from overflow)" if derived else ""
    raise SpecError(f"expected a finite number, got {value!r}{how}", file=where.file, line=where.line, field=field)


def _walk(x, path: str, where: Where, derived: str | None) -> None:
    if isinstance(x, bool) or x is None or isinstance(x, (str, int)):
        return
    if isinstance(x, float):
        if not math.isfinite(x):
            _fail(where, path, x, derived)
        return
    if isinstance(x, Rigid3):
        _walk(np.asarray(x.matrix), path, where, derived)
        return
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "fc" and not np.isfinite(x).all():
            k = np.unravel_index(int(np.argmax(~np.isfinite(x))), x.shape)
            _fail(where, f"{path}[{', '.join(str(int(i)) for i in k)}]", float(x[k]), derived)
        return
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        here = getattr(x, "where", None) or where
        base = "" if here is not where else path
        for f in dataclasses.fields(x):
            if f.name in _SKIP:
                continue
            meta = spec_meta(type(x), f)
            _walk(getattr(x, f.name), f"{base}.{f.name}", here, getattr(meta, "derived", None))
        return
    if isinstance(x, (dict, MappingProxyType)):
        for k, v in x.items():
            _walk(v, f"{path}.{k}", where, derived)
        return
    if isinstance(x, (list, tuple)):
        for i, v in enumerate(x):
            _walk(v, f"{path}[{i}]", where, derived)
