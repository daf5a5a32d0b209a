"""Typed, located access to a YAML node tree (SafeLoader only; composed by :mod:`.compose`,
which refuses tags, nesting and alias expansions a hostile document could use).

The YAML text is composed, not constructed, so every value keeps its line. ``Node`` wraps one
value with its field path; its ``as_*`` readers check the type and range and raise
:class:`~scenegen.errors.SpecError` naming file, line and field. ``Fields`` wraps a mapping,
rejects unknown keys (with a difflib suggestion) and hands out required / optional members.
"""
from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Iterable, Sequence

import yaml

from scenegen.errors import SpecError, Where
from scenegen.located_yaml.compose import compose
from scenegen.located_yaml.text import non_finite_text, number_text, out_of_range_text, quoted_list, source_text, suggest

_NUMBER_RE = re.compile(r"^[-+]?(\d[\d_]*\.?[\d_]*|\.\d[\d_]*)([eE][-+]?\d+)?$")
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]*$")
#: Longest name (scene, object, camera, ...): names become file names; equal to
#: scenegen.dataset.layout.MAX_NAME_LEN (tests/hostile/test_hostile_limits.py checks).
MAX_NAME_LEN = 128


class Document:
    """A composed YAML document: the loader (for scalar construction) and the file name."""

    def __init__(self, text: str, file: str, base_dir: Path):
        self.file = file
        self.base_dir = base_dir
        self._pairs: dict[int, list] = {}
        self.loader, root = compose(text, file)
        self.root = Node(self, root, "")

    def pairs(self, node: yaml.MappingNode) -> list[tuple[yaml.Node, yaml.Node, bool]]:
        """(key, value, written_here) of a mapping after YAML merge keys ('<<') are applied;
        merged pairs come first. Cached: flattening changes the node."""
        if id(node) not in self._pairs:
            own = {id(k) for k, _ in node.value}
            try:
                self.loader.flatten_mapping(node)
            except yaml.MarkedYAMLError as e:
                mark = e.problem_mark or e.context_mark
                raise SpecError(f"invalid YAML merge: {e.problem}", file=self.file,
                                line=mark.line + 1 if mark else None) from None
            self._pairs[id(node)] = [(k, v, id(k) in own) for k, v in node.value]
        return self._pairs[id(node)]

    def where(self, node: yaml.Node | None, path: str) -> Where:
        line = node.start_mark.line + 1 if node is not None else None
        return Where(self.file, line, path or None)


class Node:
    """One YAML value with its field path."""

    __slots__ = ("doc", "node", "path")

    def __init__(self, doc: Document, node: yaml.Node | None, path: str):
        self.doc, self.node, self.path = doc, node, path

    # -- location and errors ------------------------------------------------------------------
    @property
    def where(self) -> Where:
        return self.doc.where(self.node, self.path)

    @property
    def line(self) -> int | None:
        return self.where.line

    def error(self, message: str) -> SpecError:
        return SpecError.at(self.where, message)

    def child(self, node: yaml.Node, key: str | int) -> "Node":
        if isinstance(key, int):
            return Node(self.doc, node, f"{self.path}[{key}]")
        return Node(self.doc, node, f"{self.path}.{key}" if self.path else key)

    # -- type tests ------------------------------------------------------------------------------
    @property
    def is_null(self) -> bool:
        return self.node is None or (isinstance(self.node, yaml.ScalarNode)
                                     and self.node.tag == "tag:yaml.org,2002:null")

    @property
    def is_mapping(self) -> bool:
        return isinstance(self.node, yaml.MappingNode)

    @property
    def is_sequence(self) -> bool:
        return isinstance(self.node, yaml.SequenceNode)

    def scalar(self):
        """The Python value of a scalar node (SafeLoader's rules)."""
        if self.node is None:
            return None
        try:
            return self.doc.loader.construct_object(self.node, deep=True)
        except (yaml.YAMLError, ValueError, OverflowError) as e:  # e.g. the date 2001-13-45
            problem = getattr(e, "problem", None) or str(e)
            raise self.error(f"cannot read the value {source_text(self.node) or 'here'}: {problem}") from None

    def describe(self) -> str:
        """How the value reads, for 'got ...' in messages."""
        n = self.node
        if self.is_null:
            return "nothing (null)"
        if isinstance(n, yaml.ScalarNode):
            text = repr(self.scalar())
        elif isinstance(n, yaml.SequenceNode):
            text = source_text(n) or f"a list of {len(n.value)} items"
        else:
            return "a mapping" if not source_text(n) else f"a mapping {source_text(n)}"
        return text if len(text) <= 60 else text[:57] + "..."

    # -- readers -------------------------------------------------------------------------------
    def as_str(self, what: str = "a string") -> str:
        v = self.scalar() if isinstance(self.node, yaml.ScalarNode) else None
        if not isinstance(v, str) or self.is_null:
            raise self.error(f"expected {what}, got {self.describe()}")
        return v

    def as_name(self, what: str = "a name") -> str:
        v = self.as_str(what)
        if len(v) > MAX_NAME_LEN:
            raise self.error(f"expected {what} of at most {MAX_NAME_LEN} characters (names become file "
                             f"names), got {len(v)} characters {v[:20]!r}...")
        if not NAME_RE.match(v):
            raise self.error(f"expected {what} made of letters, digits, '_' and '-' "
                             f"(starting with a letter or digit), got {v!r}")
        return v

    def as_enum(self, choices: Sequence, what: str = "") -> object:
        v = self.scalar() if isinstance(self.node, yaml.ScalarNode) else None
        if isinstance(v, bool) or v not in choices or self.is_null:
            label = f" ({what})" if what else ""
            listed = quoted_list(choices) if len(choices) <= 8 else (
                f"{quoted_list(list(choices)[:5])}, ... ({len(choices)} values)")
            raise self.error(f"expected one of {listed}{label}, got "
                             f"{self.describe()}{suggest(v, [str(c) for c in choices])}")
        return v

    def as_bool(self) -> bool:
        v = self.scalar() if isinstance(self.node, yaml.ScalarNode) else None
        if not isinstance(v, bool):
            raise self.error(f"expected true or false, got {self.describe()}")
        return v

    def _number(self):
        """int/float of a scalar, or None. Plain (unquoted) '1e-3' counts as a number although
        YAML 1.1 reads it as a string."""
        if not isinstance(self.node, yaml.ScalarNode) or self.is_null:
            return None
        v = self.scalar()
        if isinstance(v, bool):
            return None
        if isinstance(v, (int, float)):
            return v
        if isinstance(v, str) and self.node.style is None and _NUMBER_RE.match(v):
            return float(v.replace("_", ""))
        return None

    def _finite(self, unit: str) -> float:
        """The number as a finite float; 'expected a (finite) number' naming NaN, infinity or a
        value beyond float64 otherwise."""
        v = self._number()
        if v is None:
            raise self.error(f"expected a number{unit}, got {self.describe()}")
        try:
            f = float(v)
        except OverflowError:
            f = math.inf
        if not math.isfinite(f):
            raise self.error(f"expected a finite number{unit}, got {non_finite_text(self.node, v)}")
        return f

    def as_float(self, unit: str = "", *, lo: float | None = None, hi: float | None = None,
                 lo_open: bool = False, hi_open: bool = False) -> float:
        u = f" ({unit})" if unit else ""
        v = self._finite(u)
        _check_range(self, v, lo, hi, lo_open, hi_open, u)
        return v

    def as_int(self, unit: str = "", *, lo: int | None = None, hi: int | None = None) -> int:
        v = self._number()
        u = f" ({unit})" if unit else ""
        if isinstance(v, float) and not math.isfinite(v):
            raise self.error(f"expected an integer{u}, got {non_finite_text(self.node, v)}")
        if v is None or isinstance(v, float) and not v.is_integer():
            raise self.error(f"expected an integer{u}, got {self.describe()}")
        v = int(v)
        _check_range(self, v, lo, hi, False, False, u)
        return v

    def items(self, what: str = "a list") -> list["Node"]:
        if not self.is_sequence:
            raise self.error(f"expected {what}, got {self.describe()}")
        return [self.child(n, i) for i, n in enumerate(self.node.value)]

    def as_floats(self, n: int | Sequence[int] | None, unit: str = "", *,
                  lo: float | None = None, lo_open: bool = False,
                  hi: float | None = None) -> tuple[float, ...]:
        """A list of numbers; ``n`` an exact count, allowed counts, or None for any (>= 1)."""
        counts = (n,) if isinstance(n, int) else tuple(n) if n is not None else None
        u = f" ({unit})" if unit else ""
        if counts is None:
            want = "a list of numbers"
        elif len(counts) == 1:
            want = f"{counts[0]} numbers"
        else:
            want = f"{', '.join(map(str, counts[:-1]))} or {counts[-1]} numbers"
        vals = []
        if self.is_sequence:
            for item in self.items():
                v = item._number()
                if v is None:
                    vals = None
                    break
                vals.append(item._finite(u))  # NaN, infinity: named at the item
        if (not self.is_sequence or vals is None or (counts and len(vals) not in counts)
                or (counts is None and not vals)):
            got = self.describe()
            if self.is_sequence and vals is not None:
                got = f"{len(vals)} numbers {got}"
            raise self.error(f"expected {want}{u}, got {got}")
        for item, v in zip(self.items(), vals):
            _check_range(item, v, lo, hi, lo_open, False, u)
        return tuple(vals)

    def as_vec3(self, unit: str = "metres") -> tuple[float, float, float]:
        return self.as_floats(3, unit)  # type: ignore[return-value]

    def as_color(self, unit: str = "linear RGB") -> tuple[float, float, float]:
        """A non-negative number (grey) or 3 non-negative numbers."""
        if self.is_sequence:
            return self.as_floats(3, unit, lo=0.0)  # type: ignore[return-value]
        if self._number() is None:
            raise self.error(f"expected a number or 3 numbers ({unit}), got {self.describe()}")
        v = self.as_float(unit, lo=0.0)
        return (v, v, v)

    def as_mapping(self, what: str = "a mapping") -> "Fields":
        return Fields(self, what=what)

    def as_path(self, suffixes: Sequence[str], what: str) -> tuple[Path, str]:
        """An existing file, relative to the spec's directory: (absolute path, as written)."""
        text = self.as_str(f"a file path ({what})")
        if "\x00" in text or not text.strip():
            raise self.error(f"expected a file path ({what}), got {text!r}"
                             + (" (a path cannot contain a NUL byte)" if "\x00" in text else ""))
        p = Path(text).expanduser()
        try:
            full = (p if p.is_absolute() else self.doc.base_dir / p).resolve()
        except (OSError, RuntimeError) as e:  # a symlink loop, a name too long
            raise self.error(f"cannot resolve the path {text!r}: {e}") from None
        if suffixes and full.suffix.lower() not in suffixes:
            raise self.error(f"expected a {what} file ({', '.join(suffixes)}), got {text!r}")
        if full.is_dir():
            raise self.error(f"{text!r} is a directory, expected a {what} file (looked at {full})")
        if not full.is_file():
            raise self.error(f"file not found: {text!r} (looked for {full})")
        return full, text

    def plain(self):
        """The whole value as plain Python data (for pass-through parameters); rejects
        non-string keys and non-finite floats."""
        if self.is_mapping:
            f = self.as_mapping()
            return {k: f.get(k).plain() for k in f.keys()}
        if self.is_sequence:
            return [item.plain() for item in self.items()]
        v = self.scalar()
        if isinstance(v, float) and not math.isfinite(v):
            raise self.error(f"expected a finite number, got {self.describe()}")
        if not isinstance(v, (str, int, float, bool, type(None))):
            raise self.error(f"expected a string, number, true/false or null, got {self.describe()}")
        num = self._number()
        return num if isinstance(v, str) and num is not None else v


def _check_range(node: Node, v, lo, hi, lo_open, hi_open, u):
    problem = out_of_range_text(v, lo, hi, lo_open, hi_open, u)
    if problem:
        raise node.error(problem)


class Fields:
    """A YAML mapping with checked keys. Construction fails on a non-mapping, non-string or
    duplicate keys; :meth:`check` fails on keys outside the allowed set."""

    def __init__(self, owner: Node, what: str = "a mapping"):
        if not owner.is_mapping:
            raise owner.error(f"expected {what}, got {owner.describe()}")
        self.owner = owner
        self._keys: dict[str, tuple[Node, Node]] = {}
        explicit: dict[str, int] = {}  # keys written in this mapping (not merged in) -> line
        for k, v, own in owner.doc.pairs(owner.node):
            knode = Node(owner.doc, k, owner.path)
            key = knode.scalar() if isinstance(k, yaml.ScalarNode) else None
            if not isinstance(key, str):
                raise knode.error(f"expected a string key, got {knode.describe()}")
            knode = owner.child(k, key)  # the key's own line, the value's field path
            if own:
                if key in explicit:
                    raise knode.error(f"duplicate key {key!r} (first given at line "
                                      f"{explicit[key]})")
                explicit[key] = knode.line
            self._keys[key] = (knode, owner.child(v, key))  # explicit keys override merged ones

    @classmethod
    def empty(cls, owner: Node) -> "Fields":
        """No keys, errors located at ``owner`` (for shorthands like ``shape: sphere``)."""
        f = cls.__new__(cls)
        f.owner, f._keys = owner, {}
        return f

    def check(self, required: Iterable[str] = (), optional: Iterable[str] = ()) -> "Fields":
        required, optional = list(required), list(optional)
        allowed = required + optional
        for key, (knode, _) in self._keys.items():
            if key not in allowed:
                raise knode.error(
                    f"unknown key {key!r}{suggest(key, allowed)}; allowed: {', '.join(allowed)}")
        for key in required:
            if key not in self._keys:
                raise self.missing(key)
        return self

    def missing(self, key: str, hint: str = "") -> SpecError:
        path = f"{self.owner.path}.{key}" if self.owner.path else key
        return SpecError.at(Where(self.owner.doc.file, self.owner.line, path),
                            f"missing required key {key!r}{hint}")

    def keys(self) -> list[str]:
        return list(self._keys)

    def __contains__(self, key: str) -> bool:
        return key in self._keys and not self._keys[key][1].is_null

    def get(self, key: str) -> Node | None:
        """The value node, or None when absent (an explicit null counts as absent)."""
        if key not in self:
            return None
        return self._keys[key][1]

    def key_node(self, key: str) -> Node:
        """The key itself (its line), with the value's field path."""
        return self._keys[key][0]

    def value(self, key: str) -> Node:
        """The value node of a present key, null or not."""
        return self._keys[key][1]

    def req(self, key: str) -> Node:
        if key not in self:
            raise self.missing(key)
        return self._keys[key][1]

    def one_of(self, keys: Sequence[str], *, required: bool = True) -> str | None:
        """The single key of ``keys`` present; an error if several (or none and required)."""
        present = [k for k in keys if k in self]
        if len(present) > 1:
            second = self._keys[present[1]][1]
            raise second.error(f"give only one of {', '.join(keys)}; "
                               f"found {' and '.join(present)}")
        if not present:
            if required:
                path = self.owner.path or None
                raise SpecError.at(Where(self.owner.doc.file, self.owner.line, path),
                                   f"expected one of the keys {', '.join(keys)}")
            return None
        return present[0]

    def float(self, key, default=None, unit="", **kw):
        n = self.get(key)
        return default if n is None else n.as_float(unit, **kw)

    def int(self, key, default=None, unit="", **kw):
        n = self.get(key)
        return default if n is None else n.as_int(unit, **kw)

    def vec3(self, key, default=None, unit="metres"):
        n = self.get(key)
        return default if n is None else n.as_vec3(unit)
