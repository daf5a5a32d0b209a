"""Field metadata: the one place where a spec value's default, unit and range are stated.

Every value a spec author writes is a dataclass field declared with :func:`param`, which puts a
:class:`Meta` (unit, range, allowed values) into the field's metadata next to its default. The
parsers (:mod:`scenegen.spec.parse`) read default, unit and range from there with
:func:`field_info` instead of restating them; the reference table in ``docs/scene_spec.md`` is
generated from the same metadata (:mod:`scenegen.spec.reference`).

Nested records and derived values that are not written as one YAML value are declared with
:func:`part`. Classes of other packages that a spec fills in (``scenegen.geometry.optics``) get
their metadata with :func:`describe_foreign`, their defaults staying where they are.
"""
from __future__ import annotations

import copyreg
import dataclasses
import functools
import types
import typing
from dataclasses import MISSING, dataclass, field
from typing import Any, Mapping

#: Key of the spec metadata in ``dataclasses.Field.metadata``.
META_KEY = "scenegen.spec"
#: Seeds are unsigned 32-bit integers; ids signed 32-bit (the id images).
SEED_MAX = 2**32 - 1
ID_MAX = 2**31 - 1
#: World up (+z), the default ``up`` of every look-at.
WORLD_UP = (0.0, 0.0, 1.0)

_WHERE = dict(default=None, compare=False, repr=False)


class _NotGiven:
    def __repr__(self) -> str:
        return "NOT_GIVEN"


#: Marks an unset Meta.yaml_default (dataclasses' MISSING cannot be a field default).
NOT_GIVEN = _NotGiven()


@dataclass(frozen=True)
class Meta:
    """What a spec value means and which values it may take."""

    unit: str  # unit or meaning, e.g. 'metres', 'samples per pixel', 'seed', 'flag'
    label: str | None = None  # how error messages name it, where that differs from unit ('' = not)
    lo: float | None = None  # smallest allowed value (per element of a vector)
    hi: float | None = None  # largest allowed value
    lo_open: bool = False  # lo itself excluded
    hi_open: bool = False  # hi itself excluded
    choices: tuple | None = None  # allowed values of an enumeration
    derived: str | None = None  # when absent from the YAML the parser computes it (how, in words);
    # the dataclass default is then only a construction default
    yaml_default: Any = NOT_GIVEN  # the value when absent from the YAML, where it differs from the
    # construction default (e.g. a stereo rig's vergence 0 while a multi rig has None)
    part: bool = False  # a nested record or section, not one YAML value (see part())
    doc_default: str | None = None  # how the docs state the default where one value does not
    # say it (e.g. 'required for a stereo rig')
    omit_default: bool = False  # left out of the resolved spec (spec_to_dict) while at its
    # default: a field added after datasets existed, so that theirs keep their bytes and hash
    key: str | None = None  # the YAML key where it differs from the field name; one with '.',
    # '[' or ' ' is a path into a value the section's own code reads (e.g. 'size[0]')
    kind: str | None = None  # how the value is read where the type does not say it: 'color'
    # (a grey number or 3 numbers), 'range' ([min, max], min <= max), 'str'; else from the
    # annotation (see value_kind)
    count: Any = None  # allowed lengths of a list (an int, a tuple of ints, or None: any)
    # where the tuple annotation does not fix it

    @property
    def shown(self) -> str:
        """The unit as the error messages show it."""
        return self.unit if self.label is None else self.label

    def range_text(self) -> str:
        """'> 0', '>= 0 and < 1', ... or ''."""
        parts = []
        if self.lo is not None:
            parts.append(f"{'>' if self.lo_open else '>='} {_number(self.lo)}")
        if self.hi is not None:
            parts.append(f"{'<' if self.hi_open else '<='} {_number(self.hi)}")
        return " and ".join(parts)


def _number(x) -> str:
    return str(x) if isinstance(x, int) else f"{x:g}"


def param(default: Any = MISSING, *, unit: str, label: str | None = None, lo=None, hi=None,
          lo_open: bool = False, hi_open: bool = False, choices=None, derived: str | None = None,
          yaml_default: Any = NOT_GIVEN, doc_default: str | None = None,
          default_factory: Any = MISSING, omit_default: bool = False, key: str | None = None,
          kind: str | None = None, count: Any = None):
    """A dataclass field for one spec value: its default and :class:`Meta`. Parsing, writing
    back (``to_yaml``) and the docs' reference row of a value are generated from these."""
    meta = Meta(unit=unit, label=label, lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open,
                choices=tuple(choices) if choices is not None else None, derived=derived,
                yaml_default=yaml_default, doc_default=doc_default, omit_default=omit_default,
                key=key, kind=kind, count=count)
    return field(default=default, default_factory=default_factory, metadata={META_KEY: meta})


def part(default: Any = MISSING, *, unit: str, default_factory: Any = MISSING,
         omit_default: bool = False):
    """A dataclass field holding a nested record, a section or a resolved value (``unit`` says
    what it holds); absent means its default. ``omit_default``: as for :func:`param`."""
    return field(default=default, default_factory=default_factory,
                 metadata={META_KEY: Meta(unit=unit, part=True, omit_default=omit_default)})


def where_field():
    """The ``where`` of a record (file, line, field path); takes no part in equality."""
    return field(**_WHERE)


def frozen_mapping(d: Mapping | None = None) -> Mapping:
    """A read-only view of a dict (insertion order kept)."""
    return types.MappingProxyType(dict(d or {}))


# A spec pickles (a Dask worker, a SceneDescription): its read-only mappings travel as a fresh
# read-only mapping of the same items (MappingProxyType itself refuses pickling).
copyreg.pickle(types.MappingProxyType, lambda mp: (frozen_mapping, (dict(mp),)))


_FOREIGN: dict[type, dict[str, Meta]] = {}


def describe_foreign(cls: type, **metas: Meta) -> None:
    """Attach spec metadata to fields of a dataclass defined outside the spec (its defaults stay
    in that class)."""
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = set(metas) - names
    if unknown:
        raise TypeError(f"{cls.__name__} has no fields {sorted(unknown)}")
    _FOREIGN.setdefault(cls, {}).update(metas)


def meta(unit: str, **kw) -> Meta:
    """A :class:`Meta` for :func:`describe_foreign`."""
    return Meta(unit=unit, **kw)


@dataclass(frozen=True)
class FieldInfo:
    """A spec field as the parser needs it."""

    owner: type
    name: str
    meta: Meta
    default: Any  # the value when absent from the YAML; MISSING when required or derived

    @property
    def required(self) -> bool:
        return self.default is MISSING and self.meta.derived is None

    @property
    def key(self) -> str:
        """The YAML key."""
        return self.meta.key or self.name

    @property
    def written(self) -> bool:
        """One YAML value under its own key (not a part, not a path into a nested value such as
        'size[0]'): written back by the generated code (scenegen.spec.parse.fields)."""
        return not self.meta.part and not any(c in self.key for c in ".[ ")

    @property
    def plain(self) -> bool:
        """Written and not derived from other values: also read by the generated code."""
        return self.written and self.meta.derived is None

    @property
    def kind(self) -> str:
        return value_kind(self.owner, self.name, self.meta)


def spec_meta(cls: type, f: dataclasses.Field) -> Meta | None:
    """The spec metadata of field ``f`` of ``cls`` (its own, or described with
    :func:`describe_foreign`), None if it has none."""
    return f.metadata.get(META_KEY) or _FOREIGN.get(cls, {}).get(f.name)


def field_info(cls: type, name: str) -> FieldInfo:
    """Default and metadata of field ``name`` of ``cls`` (a spec dataclass, or a foreign one
    described with :func:`describe_foreign`)."""
    f = next((f for f in dataclasses.fields(cls) if f.name == name), None)
    if f is None:
        raise AttributeError(f"{cls.__name__} has no field {name!r}")
    meta_ = spec_meta(cls, f)
    if meta_ is None:
        raise TypeError(f"{cls.__name__}.{name} has no spec metadata (declare it with param())")
    return _info(cls, f, meta_)


def _info(cls: type, f: dataclasses.Field, meta_: Meta) -> FieldInfo:
    if meta_.derived is not None:
        default = MISSING
    elif meta_.yaml_default is not NOT_GIVEN:
        default = meta_.yaml_default
    elif f.default is not MISSING:
        default = f.default
    elif f.default_factory is not MISSING:
        default = f.default_factory()
    else:
        default = MISSING
    return FieldInfo(owner=cls, name=f.name, meta=meta_, default=default)


_SCALARS = {float: "float", int: "int", bool: "bool", str: "str"}


@functools.lru_cache(maxsize=None)
def _hints(cls: type) -> dict:
    return typing.get_type_hints(cls)


def value_kind(cls: type, name: str, meta_: Meta | None = None) -> str:
    """How field ``name`` of ``cls`` is read: 'enum' (it has choices), the Meta's ``kind``, else
    from its annotation (None allowed aside): 'float', 'int', 'bool', 'str', or 'floats' for a
    tuple of floats (its length from the annotation, or Meta.count). ``meta_``: the field's, if
    known."""
    m = meta_ or field_info(cls, name).meta
    if m.choices:
        return "enum"
    if m.kind:
        return m.kind
    hint = _hints(cls)[name]
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    if typing.get_origin(hint) in (typing.Union, types.UnionType) and len(args) == 1:
        hint = args[0]
    if hint in _SCALARS:
        return _SCALARS[hint]
    if typing.get_origin(hint) is tuple and set(typing.get_args(hint)) <= {float, Ellipsis}:
        return "floats"
    raise TypeError(f"{cls.__name__}.{name}: no reader for {hint!r}; give param(kind=...) or "
                    "read it in the section's parser")


def value_count(cls: type, name: str):
    """Allowed lengths of a 'floats' field: Meta.count, else the tuple annotation's."""
    m = field_info(cls, name).meta
    if m.count is not None:
        return m.count
    hint = _hints(cls)[name]
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        hint = args[0]
    elems = typing.get_args(hint)
    return None if Ellipsis in elems else len(elems)


def spec_fields(cls: type) -> list[FieldInfo]:
    """Every field of ``cls`` that carries spec metadata, in declaration order."""
    return [_info(cls, f, m) for f in dataclasses.fields(cls)
            if (m := spec_meta(cls, f)) is not None]
