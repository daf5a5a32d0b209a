"""The pattern sequences a projector shows, by name: :data:`SEQUENCES` (docs/scene_spec.md,
"Projectors"). A sequence is a (N, H, W) float64 stack of pattern values in [0, 1] at the
projector's resolution (pixel [r, c] is projector pixel column c, row r, OpenCV's convention);
the projector's radiometry (:mod:`scenegen.spec.sensors.projector`) turns a value into light.

``gray``: the structured-light sequence of Lanman and Taubin's desktop scanner: an all-white and
an all-black image, then for each axis (columns, then rows) its reflected binary Gray code bits,
most significant first, each followed by its inverse. Bit ``b`` of column ``c`` is bit ``b`` of
``c ^ (c >> 1)``; ``bits`` of a W-wide axis is ceil(log2 W) (the codes of every column).
``white``: one all-white image (the radiometry's reference).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

AXES = ("columns", "rows", "both")


def gray_code(index):
    """The reflected binary Gray code of non-negative integers (numpy arrays or ints)."""
    return index ^ (index >> 1)


def axis_bits(size: int) -> int:
    """Bits that number ``size`` projector pixels along an axis: ceil(log2(size)), at least 1."""
    return max(1, math.ceil(math.log2(size)))


@dataclass(frozen=True)
class PatternImage:
    """One pattern of a sequence: its values (H, W) in [0, 1] and what it codes: ``axis``
    ('columns', 'rows' or '' for a plain image), ``bit`` (0 = least significant; -1 for a plain
    image) and ``inverse``."""

    values: np.ndarray
    name: str
    axis: str = ""
    bit: int = -1
    inverse: bool = False


def gray_sequence(width: int, height: int, axes: str = "both", inverse: bool = True,
                  white_black: bool = True) -> tuple[PatternImage, ...]:
    """The Gray-code sequence (module docstring) of a ``width`` x ``height`` projector."""
    if axes not in AXES:
        raise ValueError(f"axes must be one of {AXES}, got {axes!r}")
    out: list[PatternImage] = []
    if white_black:
        out += [PatternImage(np.ones((height, width)), "white"), PatternImage(np.zeros((height, width)), "black")]
    for axis in ("columns", "rows"):
        if axes not in (axis, "both"):
            continue
        n = width if axis == "columns" else height
        code = gray_code(np.arange(n))
        for b in reversed(range(axis_bits(n))):
            line = ((code >> b) & 1).astype(np.float64)
            img = np.broadcast_to(line[None, :] if axis == "columns" else line[:, None], (height, width)).copy()
            out.append(PatternImage(img, f"{axis[:3]}_bit{b:02d}", axis, b, False))
            if inverse:
                out.append(PatternImage(1.0 - img, f"{axis[:3]}_bit{b:02d}_inv", axis, b, True))
    return tuple(out)


def white_sequence(width: int, height: int, **_) -> tuple[PatternImage, ...]:
    """One all-white pattern."""
    return (PatternImage(np.ones((height, width)), "white"),)


#: Sequence name -> builder(width, height, axes=, inverse=, white_black=) -> patterns.
SEQUENCES: dict[str, Callable[..., tuple[PatternImage, ...]]] = {
    "gray": gray_sequence,
    "white": white_sequence,
}
