"""A board picture on whole texels: the resolution rule, and the boards it refuses.

OpenCV draws a board picture (``CharucoBoard.generateImage``, ``GridBoard.generateImage``) on
whole pixels: a square, a marker or a gap whose edge falls inside a pixel is moved to a pixel
boundary. The stored truth is computed from the board's parameters, so it equals the printed
picture only if every edge of every square, marker, gap and margin lands on a texel boundary.

Lengths are measured in UNITS: the square side (checkerboard, ChArUco) or the marker side (ArUco
grid); a picture has ``k`` texels per unit (``k`` whole). A length ``L`` is exact at ``k`` when
``L / unit * k`` is a whole number (to :data:`WHOLE_TEXEL_TOL` texels). The lengths that must be:

* checkerboard: the margin;
* ChArUco: the marker side, the marker's offset in its square ``(square_m - marker_m) / 2``, the
  margin;
* ArUco grid: the separation, the margin.

The rule (:func:`texels_per_unit`): ``k`` is the smallest exact resolution from
:data:`PREFERRED_MIN_TEXELS` up; if none fits, the largest exact one from
:data:`MIN_TEXELS` to :data:`PREFERRED_MIN_TEXELS` - 1. A resolution fits when the picture's
longer side is at most :data:`MAX_TEXTURE_PX` texels and a marker has at least its cell count
plus two texels (OpenCV draws no smaller marker). A board with no fitting exact resolution is
refused with :class:`BoardRasterError`, which names the spec field to change.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import cv2
import numpy as np

#: The longest side of a board picture, texels (4 bytes x 3 channels each in the renderer).
MAX_TEXTURE_PX = 8192
#: Texels per unit tried first (the smallest exact resolution from here up is used).
PREFERRED_MIN_TEXELS = 100
#: The fewest texels per unit a board is drawn with.
MIN_TEXELS = 32
#: A length is a whole number of texels when within this many texels of one. Float rounding of
#: products such as 0.022 / 0.03 * 105 is ~1e-14 texels; a user's length that is not a simple
#: ratio of the unit misses every whole number by far more.
WHOLE_TEXEL_TOL = 1e-9


class BoardRasterError(ValueError):
    """A board that cannot be drawn exactly; ``field`` is the spec field to change."""

    def __init__(self, field: str, message: str):
        super().__init__(message)
        self.field = field


def aruco_dictionary(name: str):
    """The OpenCV predefined ArUco dictionary ``name`` (e.g. 'DICT_5X5_100'); ValueError if unknown."""
    const = getattr(cv2.aruco, str(name), None) if str(name).startswith("DICT_") else None
    if const is None:
        known = sorted(n for n in dir(cv2.aruco) if n.startswith("DICT_"))
        raise ValueError(f"unknown ArUco dictionary {name!r}; known: {', '.join(known)}")
    return cv2.aruco.getPredefinedDictionary(const)


def whole_texels(name: str, value_px: float) -> int:
    """``value_px`` as a whole number of texels, or ValueError naming ``name``."""
    n = int(round(value_px))
    if abs(value_px - n) > WHOLE_TEXEL_TOL or n < 0:
        raise ValueError(f"{name} is {value_px:.9g} px; it must be a whole number of pixels "
                         "(choose px_per_square / px_per_marker to make it one)")
    return n


@dataclass(frozen=True)
class Layout:
    """What the resolution rule needs of a board: its lengths in units.

    ``lengths``: (spec field, what it is, length in units) for every length that must be whole
    texels; ``size_units``: the picture's (width, height) in units; ``count_fields``: the spec
    fields counting squares / markers along x and y; ``marker_units``: the marker side in units
    (None without markers); ``marker_min_texels``: the smallest marker OpenCV draws."""

    unit: str  # 'square' or 'marker'
    unit_m: float
    lengths: tuple[tuple[str, str, float], ...]
    size_units: tuple[float, float]
    count_fields: tuple[str, str]
    marker_units: float | None = None
    marker_min_texels: int = 0


def checkerboard_layout(inner_cols: int, inner_rows: int, square_m: float, margin_m: float) -> Layout:
    m = margin_m / square_m
    return Layout("square", square_m, (("margin_m", "the margin", m),),
                  (inner_cols + 1 + 2 * m, inner_rows + 1 + 2 * m), ("inner_cols", "inner_rows"))


def charuco_layout(squares_x: int, squares_y: int, square_m: float, marker_m: float, dictionary: str,
                   margin_m: float) -> Layout:
    m = margin_m / square_m
    lengths = (("marker_m", "the marker side", marker_m / square_m),
               ("marker_m", "the marker's offset in its square, (square_m - marker_m) / 2",
                (square_m - marker_m) / (2 * square_m)),
               ("margin_m", "the margin", m))
    return Layout("square", square_m, lengths, (squares_x + 2 * m, squares_y + 2 * m),
                  ("squares_x", "squares_y"), marker_m / square_m, _marker_min(dictionary))


def aruco_layout(markers_x: int, markers_y: int, marker_m: float, separation_m: float, dictionary: str,
                 margin_m: float) -> Layout:
    s, m = separation_m / marker_m, margin_m / marker_m
    size = (markers_x + (markers_x - 1) * s + 2 * m, markers_y + (markers_y - 1) * s + 2 * m)
    return Layout("marker", marker_m, (("separation_m", "the separation", s), ("margin_m", "the margin", m)),
                  size, ("markers_x", "markers_y"), 1.0, _marker_min(dictionary))


def layout_of(target) -> Layout:
    """The :class:`Layout` of a spec target (``scenegen.spec.model`` Checkerboard/Charuco/
    ArucoGridTarget, read by attribute)."""
    kind = getattr(target, "kind", None)
    if kind == "checkerboard":
        return checkerboard_layout(target.inner_cols, target.inner_rows, target.square_m, target.margin_m)
    if kind == "charuco":
        return charuco_layout(target.squares_x, target.squares_y, target.square_m, target.marker_m,
                              target.dictionary, target.margin_m)
    if kind in ("aruco_grid", "aruco"):
        return aruco_layout(target.markers_x, target.markers_y, target.marker_m, target.separation_m,
                            target.dictionary, target.margin_m)
    raise ValueError(f"unknown calibration target kind {kind!r}")


def _marker_min(dictionary: str) -> int:
    return int(aruco_dictionary(dictionary).markerSize) + 2  # cells plus a one-cell black border


_K = np.arange(1, MAX_TEXTURE_PX + 1, dtype=np.float64)  # every resolution a picture can have


def _exact(units: float) -> np.ndarray:
    x = units * _K
    return np.abs(x - np.rint(x)) <= WHOLE_TEXEL_TOL


def _fits(layout: Layout) -> np.ndarray:
    w, h = layout.size_units
    ok = (_K >= MIN_TEXELS) & (np.rint(max(w, h) * _K) <= MAX_TEXTURE_PX)
    if layout.marker_units is not None:
        ok &= np.rint(layout.marker_units * _K) >= layout.marker_min_texels
    return ok


def texels_per_unit(layout: Layout) -> int:
    """The picture resolution of a board, texels per unit, by the rule of the module docstring;
    :class:`BoardRasterError` naming the field to change when no resolution is exact and fits."""
    fits = _fits(layout)
    exact = [_exact(u) for _, _, u in layout.lengths]
    ok = fits & np.logical_and.reduce(exact) if exact else fits
    preferred = ok & (_K >= PREFERRED_MIN_TEXELS)
    if preferred.any():
        return int(_K[np.argmax(preferred)])
    if ok.any():
        return int(_K[np.flatnonzero(ok)[-1]])
    raise _refusal(layout, fits, exact)


def _refusal(layout: Layout, fits: np.ndarray, exact: list[np.ndarray]) -> BoardRasterError:
    u = layout.unit
    limit = f"the texture limit of {MAX_TEXTURE_PX} texels per side"
    if not fits.any():
        w, h = layout.size_units
        field = layout.count_fields[0] if w >= h else layout.count_fields[1]
        least = max(MIN_TEXELS, int(np.ceil(layout.marker_min_texels / (layout.marker_units or 1.0))))
        return BoardRasterError(field, f"the board is {w:.6g} x {h:.6g} {u}s; at {least} texels per {u} "
                                       f"(the fewest it is drawn with) its picture exceeds {limit}")
    alone = [fits & e for e in exact]
    for (field, what, units), a in zip(layout.lengths, alone):
        if not a.any():
            return BoardRasterError(field, f"{what} is {units:.9g} {u}s ({units * layout.unit_m:.9g} m): "
                                           f"{_needs(units, u)}, so no picture within {limit} puts its "
                                           f"edges on whole texels (OpenCV draws on whole pixels: the "
                                           f"printed board would not be the stored one); use lengths "
                                           f"in a simple ratio to the {u} side")
    # each length alone can be exact, not all at once: blame the one needing the finest raster
    worst = max(range(len(alone)), key=lambda i: np.argmax(alone[i]))
    field, what, units = layout.lengths[worst]
    others = ", ".join(sorted({f for f, _, _ in layout.lengths if f != field})) or "the other lengths"
    return BoardRasterError(field, f"{what} ({units:.9g} {u}s) and {others} are whole texels together "
                                   f"only in a picture beyond {limit}; use lengths in a simple ratio to "
                                   f"the {u} side")


def _needs(units: float, unit: str) -> str:
    q = Fraction(units).limit_denominator(10**7)
    if abs(units * q.denominator - q.numerator) <= WHOLE_TEXEL_TOL:
        return f"it is whole only at a multiple of {q.denominator} texels per {unit}"
    return f"it is not a ratio of small whole numbers of the {unit} side"
