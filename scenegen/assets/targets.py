"""Calibration targets (checkerboard, ChArUco, ArUco grid) with exact 3D truth (no Mitsuba).

The builders return a :class:`~scenegen.assets.board.Board` (its frame: :mod:`scenegen.assets.board`).

Truth point ORDER and ids:

* checkerboard: the inner corners row-major from the top-left, x fastest:
  id = row * inner_cols + col at ((margin + 1 + col) * square, (margin + 1 + row) * square).
  The top-left square is black, and for that colouring ``cv2.findChessboardCorners(image,
  (inner_cols, inner_rows))`` returns the corners in exactly this order on an upright view (tested
  for odd and even sizes; ``findChessboardCornersSB`` may start from another corner).
* charuco: the ChArUco corners (inner chessboard corners) with OpenCV's ids, the indices of
  ``CharucoBoard.getChessboardCorners()``: row-major from the top-left, x fastest.
  Plus ``marker_corners_board`` (M, 4, 3) in OpenCV's marker corner order (top-left, top-right,
  bottom-right, bottom-left as printed) and ``marker_ids``.
* aruco grid: the points are the marker corners, (M * 4, 3), id = marker_id * 4 + corner_index,
  markers in ``GridBoard.getIds()`` order (row-major from the top-left).

All truth coordinates are computed here in float64 from the board's parameters and checked
against OpenCV's own (float32) object points when the board is built. The picture is drawn by
OpenCV (checkerboards here) at a resolution that puts every edge of every square, marker, gap and
margin on a texel boundary (:mod:`scenegen.assets.board_raster`), so the printed picture is
exactly the stored board: a builder given ``px_per_square`` / ``px_per_marker`` refuses one that
does not, and without it (None) uses the resolution rule, as :func:`board_from_spec` does.
"""
from __future__ import annotations

import cv2
import numpy as np

from scenegen.assets.board import BOARD_KINDS, Board, BoardKind
from scenegen.assets.board_raster import (
    BoardRasterError,
    aruco_dictionary,
    aruco_layout,
    charuco_layout,
    checkerboard_layout,
    layout_of,
    texels_per_unit,
    whole_texels,
)
from scenegen.assets.checks import count as _count, positive as _positive

__all__ = ["BOARD_KINDS", "Board", "BoardKind", "aruco_grid", "board_from_spec", "charuco_board",
           "checkerboard_board"]

# OpenCV stores board object points as float32: ~6e-8 relative; at board sizes of a few metres
# that is < 1e-6 m.
_CV_OBJPOINT_TOL_M = 1e-6


# --- helpers -----------------------------------------------------------------------------------


def _margin_m(margin_squares, margin_m, square_m: float) -> float:
    if margin_m is not None:
        if not margin_m >= 0:
            raise ValueError(f"margin_m must be >= 0, got {margin_m!r}")
        return float(margin_m)
    if not margin_squares >= 0:
        raise ValueError(f"margin_squares must be >= 0, got {margin_squares!r}")
    return float(margin_squares) * square_m


def _inner_corners(cols: int, rows: int, square_m: float, offset_m: float) -> np.ndarray:
    """(cols * rows, 3): inner corner (col, row) at ((1 + col) s + o, (1 + row) s + o, 0),
    row-major from the top-left, x fastest."""
    r, c = np.mgrid[0:rows, 0:cols]
    x = (1 + c.ravel()) * square_m + offset_m
    y = (1 + r.ravel()) * square_m + offset_m
    return np.stack([x, y, np.zeros_like(x)], axis=-1)


def _check_against_cv2(ours: np.ndarray, cv2_points, offset_m: float, what: str) -> None:
    """Guard against an OpenCV change of board frame (it flipped y in 4.6): ours == cv2 + offset."""
    theirs = np.asarray(cv2_points, dtype=np.float64).reshape(ours.shape).copy()
    theirs[..., :2] += offset_m
    if not np.allclose(ours, theirs, rtol=0, atol=_CV_OBJPOINT_TOL_M):
        raise RuntimeError(f"OpenCV's {what} disagree with scenegen's board frame "
                           f"(max diff {np.abs(ours - theirs).max():.3g} m); OpenCV "
                           f"{cv2.__version__} may have changed its board convention")


# --- builders ----------------------------------------------------------------------------------


def checkerboard_board(inner_cols: int, inner_rows: int, square_m: float,
                       margin_squares: float = 1.0, px_per_square: int | None = None,
                       margin_m: float | None = None) -> Board:
    """A plain checkerboard with ``inner_cols`` x ``inner_rows`` inner corners.

    (inner_cols + 1) x (inner_rows + 1) squares, the top-left one black, surrounded by a white
    margin of ``margin_squares`` squares (findChessboardCorners needs about one). Truth: the inner
    corners, ids and order as cv2.findChessboardCorners(image, (inner_cols, inner_rows)) returns
    them on an upright view (row-major from the top-left). ``margin_m``, when given, sets the
    margin in metres instead of ``margin_squares``; it must come out as whole pixels.
    ``px_per_square`` None: the resolution rule (:mod:`scenegen.assets.board_raster`).
    """
    cols = _count("inner_cols", inner_cols, 2)
    rows = _count("inner_rows", inner_rows, 2)
    s = _positive("square_m", square_m)
    margin = _margin_m(margin_squares, margin_m, s)
    if px_per_square is None:
        px_per_square = texels_per_unit(checkerboard_layout(cols, rows, s, margin))
    pps = _count("px_per_square", px_per_square, 2)
    margin_px = whole_texels("margin (margin / square_m * px_per_square)", margin / s * pps)
    nx, ny = cols + 1, rows + 1
    W, H = nx * pps + 2 * margin_px, ny * pps + 2 * margin_px
    img = np.full((H, W), 255, np.uint8)
    r = np.arange(ny * pps) // pps
    c = np.arange(nx * pps) // pps
    black = (r[:, None] + c[None, :]) % 2 == 0
    img[margin_px:margin_px + ny * pps, margin_px:margin_px + nx * pps][black] = 0
    ppm = pps / s
    margin_m = margin_px / ppm
    pts = _inner_corners(cols, rows, s, margin_m)
    return Board(kind="checkerboard", image=img, size_m=(W / ppm, H / ppm), px_per_m=ppm,
                 points_board=pts, point_ids=np.arange(len(pts)), grid=(nx, ny), square_m=s,
                 margin_m=margin_m)


def charuco_board(squares_x: int, squares_y: int, square_m: float, marker_m: float,
                  dictionary: str = "DICT_5X5_100", margin_squares: float = 0.5,
                  px_per_square: int | None = None, margin_m: float | None = None,
                  legacy_pattern: bool = False) -> Board:
    """A ChArUco board drawn by ``cv2.aruco.CharucoBoard.generateImage``.

    ``squares_x`` x ``squares_y`` squares of side ``square_m`` with markers of side ``marker_m``
    centred in the white squares, a white margin of ``margin_squares`` squares (or ``margin_m``
    metres when given). OpenCV's current layout (the top-left square black), or with
    ``legacy_pattern`` its layout before 4.6 (for an even ``squares_y`` the top-left square is
    white). The margin, the marker side and the marker's offset in its square,
    (square_m - marker_m) / 2, must come out as whole pixels; ``px_per_square`` None: the
    resolution rule (:mod:`scenegen.assets.board_raster`).
    Truth: the (squares_x - 1) * (squares_y - 1) ChArUco corners with OpenCV's ids, and the
    marker corners and ids.
    """
    sx = _count("squares_x", squares_x, 2)
    sy = _count("squares_y", squares_y, 2)
    s = _positive("square_m", square_m)
    m = _positive("marker_m", marker_m)
    if m >= s:
        raise ValueError(f"marker_m ({m}) must be smaller than square_m ({s})")
    margin = _margin_m(margin_squares, margin_m, s)
    d = aruco_dictionary(dictionary)
    if px_per_square is None:
        px_per_square = texels_per_unit(charuco_layout(sx, sy, s, m, dictionary, margin))
    pps = _count("px_per_square", px_per_square, 2)
    margin_px = whole_texels("margin (margin / square_m * px_per_square)", margin / s * pps)
    marker_px = whole_texels("marker side (marker_m / square_m * px_per_square)", m / s * pps)
    whole_texels("marker offset in its square ((square_m - marker_m) / 2 / square_m * "
                 "px_per_square)", (s - m) / (2 * s) * pps)
    if marker_px < d.markerSize + 2:
        raise ValueError(f"the marker side is {marker_px} px; {dictionary} needs at least "
                         f"{d.markerSize + 2} (raise px_per_square)")
    board = cv2.aruco.CharucoBoard((sx, sy), s, m, d)
    board.setLegacyPattern(bool(legacy_pattern))
    n_markers = len(board.getIds())
    if n_markers > len(d.bytesList):
        raise ValueError(f"{dictionary} has {len(d.bytesList)} markers; the board needs "
                         f"{n_markers}")
    W, H = sx * pps + 2 * margin_px, sy * pps + 2 * margin_px
    img = board.generateImage((W, H), marginSize=margin_px, borderBits=1)
    ppm = pps / s
    margin_m = margin_px / ppm
    pts = _inner_corners(sx - 1, sy - 1, s, margin_m)
    _check_against_cv2(pts, board.getChessboardCorners(), margin_m, "ChArUco corners")
    cv_markers = np.asarray(board.getObjPoints(), dtype=np.float64)  # (M, 4, 3)
    markers = _exact_markers_in_squares(cv_markers, s, m, margin_m)
    _check_against_cv2(markers, cv_markers, margin_m, "marker corners")
    return Board(kind="charuco", image=img, size_m=(W / ppm, H / ppm), px_per_m=ppm,
                 points_board=pts, point_ids=np.arange(len(pts)),
                 marker_corners_board=markers, marker_ids=np.asarray(board.getIds()).ravel(),
                 dictionary=str(dictionary), grid=(sx, sy), square_m=s, marker_m=m,
                 margin_m=margin_m, legacy_pattern=bool(legacy_pattern))


def _exact_markers_in_squares(cv_markers: np.ndarray, s: float, m: float, margin_m: float):
    """Float64 marker corners: each marker centred in the square OpenCV put it in, corners in
    OpenCV's order TL, TR, BR, BL (x right, y down)."""
    square = np.floor(cv_markers[:, :, :2].mean(axis=1) / s)  # (M, 2) column, row
    centre = (square + 0.5) * s + margin_m
    sign = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)
    xy = centre[:, None, :] + sign[None] * (m / 2)
    return np.concatenate([xy, np.zeros(xy.shape[:2] + (1,))], axis=-1)


def aruco_grid(markers_x: int, markers_y: int, marker_m: float, separation_m: float,
               dictionary: str = "DICT_5X5_100", margin_m: float | None = None,
               px_per_marker: int | None = None, first_id: int = 0) -> Board:
    """An ArUco grid drawn by ``cv2.aruco.GridBoard.generateImage``.

    ``markers_x`` x ``markers_y`` markers of side ``marker_m`` with gaps ``separation_m``, and a
    white margin ``margin_m`` (default: separation_m). Separation and margin must come out as
    whole pixels at ``px_per_marker`` (None: the resolution rule,
    :mod:`scenegen.assets.board_raster`). Marker ids run row by row from ``first_id``. Truth
    points: every marker corner, id = marker_id * 4 + corner (OpenCV corner order TL, TR, BR, BL).
    """
    mx = _count("markers_x", markers_x, 1)
    my = _count("markers_y", markers_y, 1)
    m = _positive("marker_m", marker_m)
    sep = _positive("separation_m", separation_m)
    margin = sep if margin_m is None else float(margin_m)
    if not margin >= 0:
        raise ValueError(f"margin_m must be >= 0, got {margin_m!r}")
    d = aruco_dictionary(dictionary)
    if px_per_marker is None:
        px_per_marker = texels_per_unit(aruco_layout(mx, my, m, sep, dictionary, margin))
    ppx = _count("px_per_marker", px_per_marker, max(8, d.markerSize + 2))
    ppm = ppx / m
    sep_px = whole_texels("separation (separation_m * px_per_marker / marker_m)", sep * ppm)
    margin_px = whole_texels("margin (margin_m * px_per_marker / marker_m)", margin * ppm)
    first = _count("first_id", first_id, 0)
    if first + mx * my > len(d.bytesList):
        raise ValueError(f"{dictionary} has {len(d.bytesList)} markers; the grid needs ids "
                         f"{first}..{first + mx * my - 1}")
    board = cv2.aruco.GridBoard((mx, my), m, sep, d,
                                np.arange(first, first + mx * my, dtype=np.int32))
    W = mx * ppx + (mx - 1) * sep_px + 2 * margin_px
    H = my * ppx + (my - 1) * sep_px + 2 * margin_px
    img = board.generateImage((W, H), marginSize=margin_px, borderBits=1)
    margin_m_exact = margin_px / ppm
    ids = np.asarray(board.getIds()).ravel()
    k = np.arange(mx * my)
    tl = np.stack([(k % mx) * (m + sep), (k // mx) * (m + sep)], axis=-1) + margin_m_exact
    sign = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=np.float64)
    xy = tl[:, None, :] + sign[None] * m
    markers = np.concatenate([xy, np.zeros(xy.shape[:2] + (1,))], axis=-1)  # (M, 4, 3)
    _check_against_cv2(markers, board.getObjPoints(), margin_m_exact, "marker corners")
    return Board(kind="aruco", image=img, size_m=(W / ppm, H / ppm), px_per_m=ppm,
                 points_board=markers.reshape(-1, 3),
                 point_ids=(ids[:, None] * 4 + np.arange(4)[None]).ravel(),
                 marker_corners_board=markers, marker_ids=ids, dictionary=str(dictionary),
                 grid=(mx, my), marker_m=m, separation_m=sep, margin_m=margin_m_exact)


# --- from the scene spec ----------------------------------------------------------------------


def board_from_spec(target) -> Board:
    """Build the Board for a spec target (``scenegen.spec.model`` Checkerboard/Charuco/
    ArucoGridTarget, read by attribute so this module does not import the spec layer).

    The picture resolution is :func:`scenegen.assets.board_raster.texels_per_unit` of the target
    (the spec parser refuses, naming the field, a target that has none). The Board is in the BOARD
    frame (:mod:`scenegen.assets.board`); the spec's object frame (centred, facing +z) is
    ``board.object_from_board()``.
    """
    kind = getattr(target, "kind", None)
    try:
        px = texels_per_unit(layout_of(target))
    except BoardRasterError as e:
        raise BoardRasterError(e.field, f"{kind} target: no picture resolution puts every length on "
                                        f"whole pixels: {e.field}: {e}") from None
    if kind == "checkerboard":
        return checkerboard_board(target.inner_cols, target.inner_rows, target.square_m,
                                  px_per_square=px, margin_m=target.margin_m)
    if kind == "charuco":
        return charuco_board(target.squares_x, target.squares_y, target.square_m, target.marker_m,
                             dictionary=target.dictionary, px_per_square=px, margin_m=target.margin_m,
                             legacy_pattern=bool(getattr(target, "legacy_pattern", False)))
    return aruco_grid(target.markers_x, target.markers_y, target.marker_m, target.separation_m,
                      dictionary=target.dictionary, margin_m=target.margin_m, px_per_marker=px,
                      first_id=getattr(target, "first_id", 0))
