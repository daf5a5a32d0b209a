"""How YAML values read in messages: a node's own source text, numbers, non-finite values."""
from __future__ import annotations

import math

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
