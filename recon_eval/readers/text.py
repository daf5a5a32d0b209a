"""Reading a text file, with a clear error for binary or non-UTF-8 content."""
from __future__ import annotations

from pathlib import Path

from recon_eval.errors import InputError


def read_text(path: Path, expected: str) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file (expected {expected})") from None
