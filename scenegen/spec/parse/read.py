"""Readers of one spec value that take default, unit and range from the dataclass field
(:func:`scenegen.spec.model.meta.field_info`), so that no parser restates them.

Each reader takes the mapping (:class:`~scenegen.located_yaml.Fields`), the dataclass and the
field name, and the YAML key where it differs from the field name. ``default=`` is only for
fields whose spec default is derived from other values (their metadata says ``derived``): a
literal default for any other field is refused, so a default cannot be stated twice.
"""
from __future__ import annotations

from dataclasses import MISSING
from typing import Any

from scenegen.located_yaml import Fields, Node
from scenegen.spec.model.meta import FieldInfo, field_info

_UNSET: Any = object()


def info(cls: type, name: str, default: Any = _UNSET) -> tuple[FieldInfo, Any]:
    """(field info, the default to use when the key is absent: None when required)."""
    fi = field_info(cls, name)
    if default is not _UNSET:
        if fi.meta.derived is None:
            raise TypeError(f"{cls.__name__}.{name} has a fixed default in its dataclass; the "
                            "parser must not give another")
        return fi, default
    return fi, None if fi.default is MISSING else fi.default


def value_node(f: Fields, key: str, fi: FieldInfo) -> Node | None:
    """The value of ``key``, or None when absent; a required key given as null is returned (its
    reader then says "expected ..., got nothing (null)")."""
    node = f.get(key)
    if node is None and fi.required and key in f.keys():
        return f.value(key)
    return node


def bounds(fi: FieldInfo, *, opens: bool = True) -> dict:
    """Keyword arguments of the located_yaml readers for the field's range."""
    m = fi.meta
    kw = {k: v for k, v in (("lo", m.lo), ("hi", m.hi)) if v is not None}
    if opens:
        kw.update({k: True for k, v in (("lo_open", m.lo_open), ("hi_open", m.hi_open)) if v})
    return kw


def option_in_range(cls: type, name: str, value: int, option: str) -> int:
    """``value`` of a command-line option that stands for spec field ``name`` of ``cls`` (``--spp``
    for ``render.spp``), held to the field's own range (the spec's limits, e.g. MAX_SPP), so an
    option cannot ask for what the spec may not; ValueError naming the option otherwise."""
    m = field_info(cls, name).meta
    bad_lo = m.lo is not None and (value <= m.lo if m.lo_open else value < m.lo)
    bad_hi = m.hi is not None and (value >= m.hi if m.hi_open else value > m.hi)
    if bad_lo or bad_hi:
        parts = [f"{op} {bound:,}" for op, bound in ((">" if m.lo_open else ">=", m.lo),
                                                     ("<" if m.hi_open else "<=", m.hi)) if bound is not None]
        raise ValueError(f"{option}: expected a whole number {' and '.join(parts)} ({m.unit}; the spec's "
                         f"limit, docs/scene_spec.md), got {value:,}")
    return value


def read_float(f: Fields, cls: type, name: str, key: str | None = None, *, default: Any = _UNSET,
               **override) -> float | None:
    """A number; ``override`` replaces range bounds that depend on other values."""
    fi, dflt = info(cls, name, default)
    node = value_node(f, key or name, fi)
    return dflt if node is None else node.as_float(fi.meta.shown, **{**bounds(fi), **override})


def read_int(f: Fields, cls: type, name: str, key: str | None = None, *,
             default: Any = _UNSET) -> int | None:
    fi, dflt = info(cls, name, default)
    node = value_node(f, key or name, fi)
    return dflt if node is None else node.as_int(fi.meta.shown, **bounds(fi, opens=False))


def read_vec3(f: Fields, cls: type, name: str, key: str | None = None, *,
              default: Any = _UNSET) -> tuple[float, float, float] | None:
    fi, dflt = info(cls, name, default)
    node = value_node(f, key or name, fi)
    return dflt if node is None else node.as_vec3(fi.meta.shown)


def read_floats(f: Fields, cls: type, name: str, n, key: str | None = None, *,
                default: Any = _UNSET) -> tuple[float, ...] | None:
    """``n`` numbers (an exact count, allowed counts, or None for any), each in the field's range
    (an open upper bound is the caller's to check: the list reader has none)."""
    fi, dflt = info(cls, name, default)
    node = value_node(f, key or name, fi)
    if node is None:
        return dflt
    kw = bounds(fi)
    kw.pop("hi_open", None)
    return node.as_floats(n, fi.meta.shown, **kw)


def read_enum(f: Fields, cls: type, name: str, key: str | None = None, *,
              choices=None) -> Any:
    """One of the field's ``choices`` (or the given ones), named by its unit in messages."""
    fi, dflt = info(cls, name)
    node = value_node(f, key or name, fi)
    return dflt if node is None else node.as_enum(choices or fi.meta.choices, fi.meta.shown)


def seed_or_none(f: Fields, cls: type, name: str = "seed", key: str | None = None) -> int | None:
    """An explicit seed, or None (then the caller derives one)."""
    return read_int(f, cls, name, key, default=None)
