"""Reading a text file, with a clear error for binary or non-UTF-8 content."""
from __future__ import annotations

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
