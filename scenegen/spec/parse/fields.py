"""The generated part of the parser and of its inverse (``to_yaml``): every plain field of a
spec dataclass (one YAML value under its own key, :attr:`scenegen.spec.model.meta.FieldInfo.plain`)
is read from its metadata alone -- key, reader (from the annotation,
:func:`~scenegen.spec.model.meta.value_kind`), unit, range, choices and default -- so that adding
such a field is one line in the model. The section parsers call these and keep only what spans
fields (cross-field checks, derived values, ``type:`` dispatch, names and references).
:func:`write_fields` is the inverse of :func:`read_fields` for :mod:`scenegen.spec.to_yaml`.
"""
from __future__ import annotations

from typing import Any, Iterable

from scenegen.located_yaml import Fields, Node
from scenegen.spec.model.meta import FieldInfo, spec_fields, value_count
from scenegen.spec.parse.read import bounds, value_node


def read_value(node: Node, fi: FieldInfo) -> Any:
    """The value of ``node`` as field ``fi`` takes it (messages name the field's unit)."""
    m, kind = fi.meta, fi.kind
    if kind == "float":
        return node.as_float(m.shown, **bounds(fi))
    if kind == "int":
        return node.as_int(m.shown, **bounds(fi, opens=False))
    if kind == "bool":
        return node.as_bool()
    if kind == "enum":
        return node.as_enum(m.choices, m.shown)
    if kind == "str":
        return node.as_str(m.shown or "a string")
    if kind == "floats":
        kw = bounds(fi)
        kw.pop("hi_open", None)  # the list reader has no open upper bound
        return node.as_floats(value_count(fi.owner, fi.name), m.shown, **kw)
    if kind == "range":
        a, b = node.as_floats(2, f"min and max, {m.unit}", lo=m.lo, lo_open=m.lo_open)
        if a > b:
            raise node.error(f"expected min <= max, got [{a:g}, {b:g}]")
        return (a, b)
    if kind == "color":
        color = node.as_color(m.shown)
        if m.hi is not None and max(color) > m.hi:
            raise node.error(f"expected {fi.name} in [{m.lo or 0:g}, {m.hi:g}] ({m.shown}), "
                             f"got {color}")
        return color
    raise TypeError(f"{fi.owner.__name__}.{fi.name}: unknown value kind {kind!r}")


def plain_fields(cls: type, skip: Iterable[str] = ()) -> list[FieldInfo]:
    """The plain fields of ``cls`` (declaration order), less those named in ``skip``."""
    skip = set(skip)
    return [fi for fi in spec_fields(cls) if fi.plain and fi.name not in skip]


def written_fields(cls: type, skip: Iterable[str] = ()) -> list[FieldInfo]:
    """The fields of ``cls`` written as one value under their own key: the plain ones and those
    derived when absent (declaration order), less those named in ``skip``."""
    skip = set(skip)
    return [fi for fi in spec_fields(cls) if fi.written and fi.name not in skip]


def yaml_keys(cls: type, skip: Iterable[str] = ()) -> tuple[str, ...]:
    """The YAML keys of the written fields of ``cls``."""
    return tuple(fi.key for fi in written_fields(cls, skip))


def required_keys(cls: type, skip: Iterable[str] = ()) -> tuple[str, ...]:
    return tuple(fi.key for fi in written_fields(cls, skip) if fi.required)


def nested_fields(cls: type, within: str) -> list[tuple[str, FieldInfo]]:
    """(key inside ``within``, field) of the fields of ``cls`` written as ``<within>.<key>``
    (e.g. ``circle.radius_m``: a value of a nested mapping the section checks by hand)."""
    n = len(within) + 1
    return [(fi.key[n:], fi) for fi in spec_fields(cls)
            if not fi.meta.part and fi.key.startswith(within + ".")]


def read_field(f: Fields, fi: FieldInfo, key: str | None = None) -> Any:
    """The field's value in ``f`` (under ``key``, default its own), or its default when absent
    (None when required: the key check has then already failed)."""
    node = value_node(f, key or fi.key, fi)
    if node is None:
        return None if fi.required else fi.default
    return read_value(node, fi)


def read_fields(f: Fields, cls: type, skip: Iterable[str] = (), *,
                within: str | None = None) -> dict[str, Any]:
    """{field name: value or default} of every plain field of ``cls`` not in ``skip``; with
    ``within``, of the fields written inside that nested mapping (``f`` is that mapping)."""
    if within is not None:
        return {fi.name: read_field(f, fi, key) for key, fi in nested_fields(cls, within)
                if fi.name not in set(skip) and fi.meta.derived is None}
    return {fi.name: read_field(f, fi) for fi in plain_fields(cls, skip)}


def read_given(f: Fields, cls: type, skip: Iterable[str] = ()) -> dict[str, Any]:
    """{field name: value} of the written fields present in ``f`` only, derived ones included
    (overrides of a base such as an imaging preset)."""
    return {fi.name: read_value(f.get(fi.key), fi) for fi in written_fields(cls, skip)
            if fi.key in f}


def check_keys(f: Fields, cls: type, skip: Iterable[str] = (), *, required: Iterable[str] = (),
               optional: Iterable[str] = ()) -> Fields:
    """``f`` with its keys checked against the written fields of ``cls`` -- ``required`` (e.g.
    ``type``) and the required fields first, then the others in declaration order, then
    ``optional`` (keys the section reads by hand)."""
    needed = tuple(required) + required_keys(cls, skip)
    return f.check(required=needed, optional=[k for k in yaml_keys(cls, skip) if k not in needed]
                   + [k for k in optional if k not in needed])


def record_mapping(node: Node, cls: type, noun: str, skip: Iterable[str] = ()) -> Fields:
    """``node`` as the mapping of a record of ``cls``: '<noun> (key, key, ...)' expected, its
    keys checked (:func:`check_keys`)."""
    return check_keys(node.as_mapping(f"{noun} ({', '.join(yaml_keys(cls, skip))})"), cls, skip)


def parse_record(node: Node, cls: type, noun: str):
    """A record of ``cls`` whose fields are all plain (e.g. a thin lens, a shutter)."""
    return cls(**read_fields(record_mapping(node, cls, noun), cls))


def write_fields(obj, skip: Iterable[str] = (), *, within: str | None = None) -> dict[str, Any]:
    """{YAML key: value} of the written fields of the record ``obj`` (tuples as lists), the
    inverse of :func:`read_fields` (``within``: of those inside that nested mapping); None
    values are left out (absent means None, or the value derived from the others)."""
    pairs = (nested_fields(type(obj), within) if within is not None
             else [(fi.key, fi) for fi in written_fields(type(obj))])
    out = {}
    for key, fi in pairs:
        v = getattr(obj, fi.name)
        if fi.name in skip or v is None:
            continue
        out[key] = plain_value(v)
    return out


def plain_value(x):
    """Tuples as lists, numpy scalars as Python numbers (YAML-safe)."""
    if isinstance(x, (tuple, list)):
        return [plain_value(e) for e in x]
    if hasattr(x, "tolist"):
        return x.tolist()
    return x
