"""Reading a text file, with a clear error for binary or non-UTF-8 content."""
from __future__ import annotations

import json
import re
from pathlib import Path

from recon_eval.errors import InputError


def read_text(path: Path, expected: str) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file (expected {expected})") from None


def bracket_depth(text: str) -> int:
    """The deepest nesting of ``[`` and ``{`` in ``text`` (brackets inside quotes counted too: an
    upper bound). For parsers that recurse in C without a limit (OpenCV's FileStorage crashes the
    process on a few thousand levels), checked before the text reaches them."""
    depth = deepest = 0
    for ch in text:
        if ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth -= 1
    return deepest


_KEY_RE = re.compile(r"^( *)(- +)?([^\s:#\"'{\[-][^:#]*?|\"[^\"]*\"|'[^']*')\s*:(\s|$)")


def duplicate_key(text: str) -> tuple[int, str, int] | None:
    """(line, key, line of its first use) of the first key given twice in one mapping of a block
    YAML or JSON text, or None. For files read by parsers that let the last key win silently
    (OpenCV's FileStorage): a calibration with two camera matrices is refused, not half read.
    JSON is checked exactly; YAML by its block structure (indentation; flow mappings unchecked)."""
    if text.lstrip().startswith("{"):
        found: list = []

        def pairs(items):
            seen = set()
            for k, _ in items:
                if k in seen and not found:
                    found.append(k)
                seen.add(k)
            return dict(items)
        try:
            json.loads(text, object_pairs_hook=pairs)
        except (ValueError, RecursionError):
            return None  # the parser reports what is wrong with it
        if not found:
            return None
        key = found[0]
        lines = [n for n, ln in enumerate(text.splitlines(), 1) if f'"{key}"' in ln]
        return (lines[1] if len(lines) > 1 else lines[0] if lines else 1), key, (lines[0] if lines else 1)
    stack: list[tuple[int, dict]] = []  # (indent, {key: line}) of the open mappings
    for n, line in enumerate(text.splitlines(), 1):
        m = _KEY_RE.match(line)
        if not m or line.startswith(("%", "---")):
            continue
        indent, dash, key = len(m.group(1)), m.group(2), m.group(3).strip("\"'")
        if dash:  # "- key:" opens a new mapping inside a list item
            while stack and stack[-1][0] >= indent:
                stack.pop()
            stack.append((indent + len(dash), {key: n}))
            continue
        while stack and stack[-1][0] > indent:
            stack.pop()
        if not stack or stack[-1][0] < indent:
            stack.append((indent, {}))
        keys = stack[-1][1]
        if key in keys:
            return n, key, keys[key]
        keys[key] = n
    return None


def json_document(text: str, path, what: str):
    """Parsed JSON of ``path``; InputError for invalid JSON, nesting too deep for the parser, or
    a key given twice in one object (the last would win silently)."""
    def pairs(items):
        d = {}
        for k, v in items:
            if k in d:
                raise InputError(f"{path}: duplicate key {k!r} in {what}")
            d[k] = v
        return d
    try:
        return json.loads(text, object_pairs_hook=pairs)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}:{exc.lineno}: invalid JSON ({exc.msg}) in {what}") from None
    except RecursionError:
        raise InputError(f"{path}: invalid JSON (nested too deeply) in {what}") from None
