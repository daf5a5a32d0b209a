"""Every board is exact by construction: the picture OpenCV draws is the board whose corners are
stored (scenegen.assets.board_raster's resolution rule), or the spec is refused naming the field.

The property test draws random boards (square and marker sizes, margins, dictionaries, rows,
columns, OpenCV's legacy ChArUco layout) and rebuilds each picture from the stored truth alone:
white paper, black squares between the stored chessboard corners, and each marker's own
``generateImageMarker`` image between its stored corners. The drawn picture must equal it pixel
for pixel, and every stored coordinate must sit on a texel boundary to float precision. The
resolution is checked against an independent oracle in exact rational arithmetic.
"""
from __future__ import annotations

import math
from fractions import Fraction
from types import SimpleNamespace

import cv2
import numpy as np
import pytest

from scenegen.assets import board_raster as br, targets
from scenegen.errors import SpecError
from scenegen.spec import parse_spec
from scenegen.spec.model.geometry import ARUCO_DICTIONARIES

# A stored coordinate times px_per_m is a whole texel to this (float64 rounding of products of
# user decimals is ~1e-13 texels at these sizes).
TEXEL_EXACT = 1e-9
N_BOARDS = 200


# --- the picture implied by the stored truth ------------------------------------------------------
def _texels(board, xy_m) -> np.ndarray:
    """Board-frame metres -> texel boundaries (whole numbers), asserting they are whole."""
    t = np.asarray(xy_m, np.float64) * board.px_per_m
    err = np.abs(t - np.rint(t)).max(initial=0.0)
    assert err <= TEXEL_EXACT, f"a stored coordinate is {err:.3g} texels off a texel boundary"
    return np.rint(t).astype(np.int64)


def _paint_markers(board, img) -> None:
    d = br.aruco_dictionary(board.dictionary)
    for mid, corners in zip(board.marker_ids, board.marker_corners_board):
        t = _texels(board, corners[:, :2])  # TL, TR, BR, BL
        x0, y0 = t[0]
        x1, y1 = t[2]
        assert (t[1] == (x1, y0)).all() and (t[3] == (x0, y1)).all() and x1 - x0 == y1 - y0
        img[y0:y1, x0:x1] = cv2.aruco.generateImageMarker(d, int(mid), int(x1 - x0), borderBits=1)


def _square_lines(board, inner_cols, inner_rows) -> tuple[np.ndarray, np.ndarray]:
    """Texel positions of the chessboard's column and row boundaries, from the stored corners."""
    p = board.points_board.reshape(inner_rows, inner_cols, 3)
    xs, ys = p[0, :, 0], p[:, 0, 1]
    s = board.square_m
    return (_texels(board, np.r_[xs[0] - s, xs, xs[-1] + s]),
            _texels(board, np.r_[ys[0] - s, ys, ys[-1] + s]))


def picture_from_truth(board) -> np.ndarray:
    h, w = board.image.shape
    assert (w, h) == tuple(_texels(board, board.size_m))
    img = np.full((h, w), 255, np.uint8)
    if board.kind == "aruco":
        _paint_markers(board, img)
        return img
    nx, ny = board.grid
    cx, cy = _square_lines(board, nx - 1, ny - 1)
    if board.kind == "checkerboard":
        black = lambda r, c: (r + c) % 2 == 0  # noqa: E731  the top-left square is black
    else:  # ChArUco: the squares without a marker are black (every white square has one)
        centres = board.marker_corners_board[:, :, :2].mean(axis=1)
        with_marker = {(int(np.searchsorted(cy, y * board.px_per_m) - 1),
                        int(np.searchsorted(cx, x * board.px_per_m) - 1)) for x, y in centres}
        assert len(with_marker) == len(board.marker_ids)
        black = lambda r, c: (r, c) not in with_marker  # noqa: E731
    for r in range(ny):
        for c in range(nx):
            if black(r, c):
                img[cy[r]:cy[r + 1], cx[c]:cx[c + 1]] = 0
    if board.kind == "charuco":
        _paint_markers(board, img)
    return img


# --- an independent oracle for the resolution rule (exact rationals) -------------------------------
def oracle_texels(kind: str, p: dict) -> int | None:
    F = lambda k: Fraction(p[k])  # noqa: E731  the decimal strings as written
    unit = F("square_m") if kind != "aruco_grid" else F("marker_m")
    margin = F("margin_m")
    if kind == "checkerboard":
        ratios = [margin / unit]
        w, h = p["inner_cols"] + 1 + 2 * margin / unit, p["inner_rows"] + 1 + 2 * margin / unit
        marker, least = None, 0
    elif kind == "charuco":
        m = F("marker_m")
        ratios = [m / unit, (unit - m) / (2 * unit), margin / unit]
        w, h = p["squares_x"] + 2 * margin / unit, p["squares_y"] + 2 * margin / unit
        marker, least = m / unit, br.aruco_dictionary(p["dictionary"]).markerSize + 2
    else:
        sep = F("separation_m") / unit
        ratios = [sep, margin / unit]
        w = p["markers_x"] + (p["markers_x"] - 1) * sep + 2 * margin / unit
        h = p["markers_y"] + (p["markers_y"] - 1) * sep + 2 * margin / unit
        marker, least = Fraction(1), br.aruco_dictionary(p["dictionary"]).markerSize + 2
    step = math.lcm(*(r.denominator for r in ratios))
    ok = [k for k in range(step, br.MAX_TEXTURE_PX + 1, step)
          if k >= br.MIN_TEXELS and max(w, h) * k <= br.MAX_TEXTURE_PX and (marker is None or marker * k >= least)]
    preferred = [k for k in ok if k >= br.PREFERRED_MIN_TEXELS]
    return preferred[0] if preferred else (ok[-1] if ok else None)


# --- random boards ------------------------------------------------------------------------------------
def _mm(x) -> str:
    return f"{x / 1000:.4f}"  # metres, as a user writes them


def random_board(rng) -> tuple[str, dict]:
    kind = rng.choice(["charuco"] * 3 + ["checkerboard", "aruco_grid"])
    step = rng.choice([1.0, 0.5, 0.1])  # lengths in whole mm, half mm or tenths of a mm
    q = lambda lo, hi: round(rng.uniform(lo, hi) / step) * step  # noqa: E731
    dictionaries = sorted(ARUCO_DICTIONARIES)
    if kind == "checkerboard":
        s = q(10, 60)
        return kind, {"inner_cols": int(rng.integers(2, 10)), "inner_rows": int(rng.integers(2, 10)),
                      "square_m": _mm(s), "margin_m": _mm(rng.choice([s, q(0, s)]))}
    if kind == "charuco":
        sx, sy = int(rng.integers(2, 9)), int(rng.integers(2, 9))
        s = q(10, 60)
        m = min(q(0.45 * s, 0.9 * s), s - step)
        fits = [d for d in dictionaries if ARUCO_DICTIONARIES[d] >= sx * sy // 2]
        return kind, {"squares_x": sx, "squares_y": sy, "square_m": _mm(s), "marker_m": _mm(m),
                      "dictionary": str(rng.choice(fits)), "margin_m": _mm(rng.choice([s, q(0, s)])),
                      "legacy_pattern": bool(rng.integers(2))}
    mx, my = int(rng.integers(1, 7)), int(rng.integers(1, 7))
    m = q(10, 60)
    sep = max(q(1, 0.4 * m), step)
    fits = [d for d in dictionaries if ARUCO_DICTIONARIES[d] >= mx * my]
    return kind, {"markers_x": mx, "markers_y": my, "marker_m": _mm(m), "separation_m": _mm(sep),
                  "dictionary": str(rng.choice(fits)), "margin_m": _mm(rng.choice([sep, q(0, m)])),
                  "first_id": 0}


def _target(kind: str, p: dict) -> SimpleNamespace:
    return SimpleNamespace(kind=kind, **{k: (float(v) if k.endswith("_m") else v) for k, v in p.items()})


def test_random_boards_print_exactly_their_stored_truth():
    rng = np.random.default_rng(20)
    drawn, refused, kinds, legacy_even = 0, 0, set(), 0
    while drawn < N_BOARDS:
        kind, p = random_board(rng)
        t = _target(kind, p)
        want = oracle_texels(kind, p)
        if want is None:
            with pytest.raises(br.BoardRasterError) as e:
                br.texels_per_unit(br.layout_of(t))
            assert e.value.field in p, (kind, p, e.value.field)
            refused += 1
            continue
        assert br.texels_per_unit(br.layout_of(t)) == want, (kind, p)
        board = targets.board_from_spec(t)
        unit = board.square_m if board.kind != "aruco" else board.marker_m
        assert board.px_per_m * unit == pytest.approx(want, rel=1e-12)
        expected = picture_from_truth(board)  # asserts every stored corner is on a texel boundary
        diff = np.argwhere(board.image != expected)
        assert len(diff) == 0, (kind, p, f"{len(diff)} texels differ, first at (row, col) {diff[0]}")
        drawn += 1
        kinds.add(kind)
        legacy_even += bool(p.get("legacy_pattern")) and p["squares_y"] % 2 == 0
    assert kinds == {"checkerboard", "charuco", "aruco_grid"} and legacy_even >= 10
    assert refused >= 1  # the generator reaches boards that cannot be drawn exactly


def test_the_issue_board_was_half_a_texel_off_and_is_exact_now():
    """The old rule (a whole marker side only) drew the issue's board at 100 px per square: each
    marker 12.5 px into its square, which OpenCV prints on whole pixels, so the printed markers
    miss the stored corners by half a texel. The rule now refuses 100 and takes 104."""
    with pytest.raises(ValueError, match=r"marker offset .* is 12\.5 px"):
        targets.charuco_board(6, 5, 0.04, 0.03, dictionary="DICT_6X6_50", px_per_square=100, margin_m=0.04)
    b = targets.charuco_board(6, 5, 0.04, 0.03, dictionary="DICT_6X6_50", margin_m=0.04)
    assert b.px_per_m * 0.04 == pytest.approx(104)  # the smallest exact resolution >= 100
    assert np.array_equal(b.image, picture_from_truth(b))
    # what the old rule printed: the stored corners at 100 px per square vs each marker's black box
    old = b.cv2_board().generateImage((800, 700), marginSize=100, borderBits=1)
    off = [raster_marker_corners(old, c[:, :2] * 2500.0 - 0.5) - c[:, :2] * 2500.0 for c in b.marker_corners_board]
    assert np.allclose(np.abs(off), 0.5)


def raster_marker_corners(img, corners_px) -> np.ndarray:
    """(4, 2) texel-boundary corners (TL, TR, BR, BL) of the black box of the marker drawn around
    ``corners_px`` (OpenCV pixel coordinates), from the picture alone."""
    (x0, y0), (x1, y1) = np.floor(corners_px.min(axis=0)).astype(int) - 2, np.ceil(corners_px.max(axis=0)).astype(int) + 3
    ys, xs = np.nonzero(img[y0:y1, x0:x1] == 0)
    l, t, r, b = xs.min() + x0, ys.min() + y0, xs.max() + x0 + 1, ys.max() + y0 + 1
    return np.array([[l, t], [r, t], [r, b], [l, b]], np.float64)


# --- the rule's refusals name the field -------------------------------------------------------------
def _charuco_yaml(**kw) -> str:
    p = {"squares_x": 6, "squares_y": 5, "square_m": 0.04, "marker_m": 0.03, "dictionary": "DICT_6X6_50", **kw}
    body = ", ".join(f"{k}: {v}" for k, v in p.items())
    return ("name: t\nobjects:\n  - name: board\n    target: {type: charuco, " + body + "}\n"
            "cameras:\n  cam: {size: [64, 48], fx: 50}\n"
            "views:\n  - camera: cam\n    look_at: [{eye: [0, 0, 1], target: [0, 0, 0], up: [0, -1, 0]}]\n")


@pytest.mark.parametrize("kw, field, message", [
    ({"marker_m": 0.0301234567}, "marker_m", "not a ratio of small whole numbers"),
    ({"squares_x": 300, "dictionary": "DICT_4X4_1000"}, "squares_x", "exceeds the texture limit of 8192"),
    ({"margin_m": 0.0000777}, "margin_m", "whole only at a multiple of 400000 texels per square"),
    # marker alone: 200 texels per square, margin alone: 300; both: 600 -> 8428 texels > 8192
    ({"squares_x": 14, "square_m": 0.03, "marker_m": 0.0201, "margin_m": 0.0007, "dictionary": "DICT_4X4_50"},
     "margin_m", "together only in a picture beyond the texture limit"),
])
def test_spec_refuses_boards_that_cannot_be_drawn_exactly(kw, field, message):
    with pytest.raises(SpecError) as e:
        parse_spec(_charuco_yaml(**kw), file="board.yaml")
    assert e.value.field == f"objects[0].target.{field}" and e.value.line == 4, str(e.value)
    assert message in str(e.value) and str(e.value).startswith(f"board.yaml:4: objects[0].target.{field}: ")


def test_spec_accepts_the_issue_board_and_the_bundled_charuco():
    for kw in ({}, {"square_m": 0.03, "marker_m": 0.022, "dictionary": "DICT_5X5_100", "squares_x": 9,
                    "squares_y": 7}):
        g = parse_spec(_charuco_yaml(**kw)).objects[0].geometry
        b = targets.board_from_spec(g)
        assert np.array_equal(b.image, picture_from_truth(b))
    assert br.texels_per_unit(br.layout_of(g)) == 105  # calib_charuco.yaml: unchanged (offset 14 px)


def test_builders_refuse_inexact_explicit_resolutions():
    with pytest.raises(ValueError, match="separation.*whole number of pixels"):
        targets.aruco_grid(2, 2, marker_m=0.04, separation_m=0.0101, px_per_marker=100)
    with pytest.raises(ValueError, match="margin .*whole number of pixels"):
        targets.checkerboard_board(4, 3, 0.05, margin_squares=0.3, px_per_square=25)
    with pytest.raises(ValueError, match="DICT_7X7_50 needs at least 9"):
        targets.charuco_board(3, 3, 0.04, 0.02, dictionary="DICT_7X7_50", px_per_square=16)
