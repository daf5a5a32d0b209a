"""PNG and EXR files for recon_eval's readers, through scenegen's codecs, which decode quietly
(:mod:`scenegen.quiet`: OpenEXR's and libpng's own lines about a malformed file never come before
recon-eval's one-line error naming the file); an EXR error always names the file and says it is
not a readable EXR file."""
from __future__ import annotations

from pathlib import Path

from scenegen.dataset import codecs
from scenegen.dataset.codecs import read_png

__all__ = ["read_png", "read_exr"]


def read_exr(path) -> dict:
    """{channel: (H, W) array} of :func:`scenegen.dataset.codecs.read_exr`; ValueError ``<path>: not a readable EXR
    file (<why>)`` whatever part of the read failed."""
    p = Path(path)
    try:
        return codecs.read_exr(p)
    except ValueError as exc:
        why = str(exc).removeprefix(f"{p}: ")
        if not why.startswith("not a readable EXR file"):
            why = f"not a readable EXR file ({why})"
        raise ValueError(f"{p}: {why}") from None
