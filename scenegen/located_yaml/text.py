"""How YAML values read in messages: a node's own source text, numbers, non-finite values,
ranges, lists of choices and the closest one."""
from __future__ import annotations

import difflib
import math
from typing import Iterable

import yaml


def non_finite_text(node: yaml.Node, v) -> str:
    """How a number that is not a finite float64 reads in a message."""
    text = source_text(node) or repr(v)
    text = text if len(text) <= 40 else f"{text[:20]}...({len(text)} characters)"
    if isinstance(v, float) and math.isnan(v):
        return f"{text} (NaN)"
    if isinstance(v, float):
        return f"{text} (infinity)"
    return f"{text} (beyond the float64 range)"


def number_text(v) -> str:
    """A number for a message: ints exactly (or as 1.2e+40 when long), floats with %g."""
    if isinstance(v, int) and not isinstance(v, bool):
        if abs(v) < 10**15:
            return str(v)
        return f"{float(v):.6g}" if abs(v) < 10**300 else f"a {len(str(abs(v)))}-digit integer"
    return f"{v:g}"


def source_text(n: yaml.Node) -> str | None:
    """The node's own text when it is short and on one line (flow style), else None."""
    s, e = n.start_mark, n.end_mark
    if s.buffer is None or s.line != e.line:
        return None
    text = s.buffer[s.index:e.index].strip()
    return text if 0 < len(text) <= 60 else None


def suggest(word: str, choices: Iterable[str]) -> str:
    """' (did you mean 'x'?)' for the closest choice, or ''."""
    close = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def quoted_list(choices: Iterable) -> str:
    return ", ".join(repr(c) for c in choices)


def out_of_range_text(v, lo, hi, lo_open: bool, hi_open: bool, unit_text: str) -> str | None:
    """'expected a value >= lo and < hi<unit_text>, got v' when ``v`` is outside the range (bounds
    None: none; ``*_open``: strict), else None."""
    bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
    bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
    if not (bad_lo or bad_hi):
        return None
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {number_text(lo)}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {number_text(hi)}")
    return f"expected a value {' and '.join(parts)}{unit_text}, got {number_text(v)}"
