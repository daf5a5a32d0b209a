"""Calibration targets (checkerboard, ChArUco, ArUco grid) with exact 3D truth (no Mitsuba).

The BOARD FRAME (metres) of every target:

* origin at the top-left corner of the physical board (margins included), x to the right along
  the picture's columns, y DOWN along its rows, z = 0 on the printed surface, so z points INTO
  the board (right-handed: x right, y down, z away from a viewer facing the print). This is the
  frame of OpenCV's calibration object points (``CharucoBoard.getChessboardCorners()`` etc.
  re-expressed with our margin); a camera that sees the print is on the board's -z side, looking
  along +z: an OpenCV camera with ``cam_from_board = (I, (tx, ty, d > 0))`` sees it upright.
* ``Board.image`` spans the physical rectangle exactly: pixel (row i, column j) covers
  x in [j, j + 1] / px_per_m and y in [i, i + 1] / px_per_m. So board point (x, y) lies at the
  OpenCV pixel coordinate (u, v) = (x * px_per_m - 0.5, y * px_per_m - 0.5) of the image
  (pixel-centre convention, :mod:`scenegen.geometry.conventions`); see :meth:`Board.points_image_px`.
* ``Board.mesh()`` is the board rectangle in this frame with its face normal along -z (towards
  the viewing side) and UVs u = x / width_m, v = y / height_m (the project's UV convention: v = 0
  at the image's top row), so the renderer textures it with ``Board.image`` pixel-exactly.

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
against OpenCV's own (float32) object points when the board is built.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
import trimesh

from scenegen.assets.checks import count as _count, positive as _positive
from scenegen.geometry.pose import Rigid3

BoardKind = str  # 'checkerboard' | 'charuco' | 'aruco'
BOARD_KINDS = ("checkerboard", "charuco", "aruco")

# OpenCV stores board object points as float32: ~6e-8 relative; at board sizes of a few metres
# that is < 1e-6 m.
_CV_OBJPOINT_TOL_M = 1e-6
# Physical lengths must land on whole pixels to within this many pixels (float rounding of
# products like 0.03 / 0.04 * 100 is ~1e-13 px; a 1e-6 px misplacement is far below any test).
_WHOLE_PX_TOL = 1e-6


def _readonly(a, dtype) -> np.ndarray:
    a = np.array(a, dtype=dtype)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Board:
    """A calibration target: its printed picture and exact 3D truth in the board frame.

    Fields (frames and units in the module docstring):
        kind: 'checkerboard', 'charuco' or 'aruco'.
        image: (H, W) uint8 picture (0 black, 255 white) spanning the physical board exactly.
        size_m: (width, height) of the physical board in metres, margins included;
            equals (W, H) / px_per_m.
        px_per_m: picture pixels per metre (the same along x and y).
        points_board: (N, 3) float64, metres, z = 0: the truth points (inner corners for
            checkerboard/ChArUco, marker corners for an ArUco grid).
        point_ids: (N,) int64 ids of points_board (see the module docstring).
        marker_corners_board: (M, 4, 3) float64, metres: marker corners (empty for checkerboard).
        marker_ids: (M,) int64 dictionary ids of the markers (empty for checkerboard).
        dictionary: OpenCV ArUco dictionary name, e.g. 'DICT_5X5_100' (None for checkerboard).
        grid: (columns, rows) of squares (checkerboard: inner_cols + 1, inner_rows + 1; charuco:
            squares_x, squares_y) or of markers (aruco).
        square_m: chessboard square side (None for aruco).
        marker_m: marker side (None for checkerboard).
        separation_m: gap between markers (aruco only, else None).
        margin_m: white border around the pattern, on every side.
    """

    kind: BoardKind
    image: np.ndarray
    size_m: tuple[float, float]
    px_per_m: float
    points_board: np.ndarray
    point_ids: np.ndarray
    marker_corners_board: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 3)))
    marker_ids: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    dictionary: str | None = None
    grid: tuple[int, int] = (0, 0)
    square_m: float | None = None
    marker_m: float | None = None
    separation_m: float | None = None
    margin_m: float = 0.0

    def __post_init__(self):
        if self.kind not in BOARD_KINDS:
            raise ValueError(f"Board.kind must be one of {BOARD_KINDS}, got {self.kind!r}")
        object.__setattr__(self, "image", _readonly(self.image, np.uint8))
        object.__setattr__(self, "points_board", _readonly(self.points_board, np.float64))
        object.__setattr__(self, "point_ids", _readonly(self.point_ids, np.int64))
        object.__setattr__(self, "marker_corners_board",
                           _readonly(self.marker_corners_board, np.float64).reshape(-1, 4, 3))
        object.__setattr__(self, "marker_ids", _readonly(self.marker_ids, np.int64))
        h, w = self.image.shape
        if not np.allclose(self.size_m, (w / self.px_per_m, h / self.px_per_m), rtol=1e-12):
            raise ValueError("Board.size_m must equal the image size / px_per_m")
        if self.points_board.shape != (len(self.point_ids), 3):
            raise ValueError("Board.points_board must be (N, 3) with N = len(point_ids)")

    @property
    def width_m(self) -> float:
        return float(self.size_m[0])

    @property
    def height_m(self) -> float:
        return float(self.size_m[1])

    def points_image_px(self) -> np.ndarray:
        """(N, 2) float64: the truth points in OpenCV pixel coordinates of :attr:`image`."""
        return self.points_board[:, :2] * self.px_per_m - 0.5

    def marker_corners_image_px(self) -> np.ndarray:
        """(M, 4, 2) float64: the marker corners in OpenCV pixel coordinates of :attr:`image`."""
        return self.marker_corners_board[:, :, :2] * self.px_per_m - 0.5

    def texture(self, black: float = 0.0, white: float = 1.0) -> np.ndarray:
        """(H, W, 3) float32 LINEAR reflectance: black -> ``black``, white -> ``white``.

        The picture is binary, so the map is linear in the stored level (not the sRGB curve):
        a texel's reflectance is then the covered fraction's average, which keeps edges (and
        corners) unbiased under the renderer's texture filtering. Real print: ~0.04 and ~0.85.
        """
        if not 0 <= black < white <= 1:
            raise ValueError(f"need 0 <= black < white <= 1, got {black!r}, {white!r}")
        t = black + (white - black) * (self.image.astype(np.float32) / 255.0)
        return np.repeat(t[..., None], 3, axis=-1).astype(np.float32)

    def mesh(self) -> trimesh.Trimesh:
        """The board rectangle in the board frame: corners (0,0,0), (w,0,0), (w,h,0), (0,h,0).

        Two triangles with face normal -z (towards the camera that sees the print), UVs
        u = x / width_m, v = y / height_m, so :attr:`image` maps onto it pixel-exactly.
        """
        w, h = self.width_m, self.height_m
        v = np.array([[0, 0, 0], [w, 0, 0], [w, h, 0], [0, h, 0]], dtype=np.float64)
        f = np.array([[0, 2, 1], [0, 3, 2]], dtype=np.int64)  # (w,h) x (w,0) -> -z
        uv = v[:, :2] / [w, h]
        return trimesh.Trimesh(vertices=v, faces=f, process=False,
                               visual=trimesh.visual.TextureVisuals(uv=uv))

    def object_from_board(self) -> Rigid3:
        """The board frame inside the spec's target object frame (board centred on the origin, in
        z = 0, print facing +z, picture upright seen from +z with +y up, as :func:`shapes.plane`).

        A 180 degree rotation about x (x -> x, y -> -y, z -> -z) plus a shift by half the board:
        the top-left corner (0, 0, 0) goes to (-width/2, +height/2, 0) and the print normal -z
        to +z. So ``world_from_board = world_from_object @ object_from_board``.
        """
        return Rigid3(np.diag([1.0, -1.0, -1.0]),
                      np.array([-self.width_m / 2, self.height_m / 2, 0.0]))

    def cv2_board(self):
        """The equivalent OpenCV board object (CharucoBoard / GridBoard), for detection.

        Its object points are in OpenCV's board frame, which is ours shifted by -margin_m in x
        and y. Checkerboards have no OpenCV board object; this raises ValueError for them.
        """
        if self.kind == "charuco":
            return cv2.aruco.CharucoBoard(self.grid, self.square_m, self.marker_m,
                                          _dictionary(self.dictionary))
        if self.kind == "aruco":
            return cv2.aruco.GridBoard(self.grid, self.marker_m, self.separation_m,
                                       _dictionary(self.dictionary),
                                       np.asarray(self.marker_ids, dtype=np.int32))
        raise ValueError("a checkerboard has no cv2.aruco board object")

    def describe(self) -> dict:
        """The board's parameters as a JSON-ready dict (no image, no points)."""
        return {"kind": self.kind, "size_m": [self.width_m, self.height_m],
                "px_per_m": self.px_per_m, "grid": list(self.grid), "square_m": self.square_m,
                "marker_m": self.marker_m, "separation_m": self.separation_m,
                "margin_m": self.margin_m, "dictionary": self.dictionary,
                "num_points": int(len(self.point_ids)), "num_markers": int(len(self.marker_ids))}


# --- helpers -----------------------------------------------------------------------------------


def _dictionary(name: str):
    const = getattr(cv2.aruco, str(name), None) if str(name).startswith("DICT_") else None
    if const is None:
        known = sorted(n for n in dir(cv2.aruco) if n.startswith("DICT_"))
        raise ValueError(f"unknown ArUco dictionary {name!r}; known: {', '.join(known)}")
    return cv2.aruco.getPredefinedDictionary(const)


def _whole_px(name: str, value_px: float) -> int:
    n = int(round(value_px))
    if abs(value_px - n) > _WHOLE_PX_TOL or n < 0:
        raise ValueError(f"{name} is {value_px:.6g} px; it must be a whole number of pixels "
                         "(choose px_per_square / px_per_marker to make it one)")
    return n


def _margin_px(margin_squares, margin_m, square_m: float, px_per_square: int) -> int:
    if margin_m is not None:
        if not margin_m >= 0:
            raise ValueError(f"margin_m must be >= 0, got {margin_m!r}")
        return _whole_px("margin (margin_m / square_m * px_per_square)",
                         margin_m / square_m * px_per_square)
    if not margin_squares >= 0:
        raise ValueError(f"margin_squares must be >= 0, got {margin_squares!r}")
    return _whole_px("margin (margin_squares * px_per_square)", margin_squares * px_per_square)


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
                       margin_squares: float = 1.0, px_per_square: int = 64,
                       margin_m: float | None = None) -> Board:
    """A plain checkerboard with ``inner_cols`` x ``inner_rows`` inner corners.

    (inner_cols + 1) x (inner_rows + 1) squares, the top-left one black, surrounded by a white
    margin of ``margin_squares`` squares (findChessboardCorners needs about one). Truth: the inner
    corners, ids and order as cv2.findChessboardCorners(image, (inner_cols, inner_rows)) returns
    them on an upright view (row-major from the top-left). ``margin_m``, when given, sets the
    margin in metres instead of ``margin_squares``; it must come out as whole pixels.
    """
    cols = _count("inner_cols", inner_cols, 2)
    rows = _count("inner_rows", inner_rows, 2)
    s = _positive("square_m", square_m)
    pps = _count("px_per_square", px_per_square, 2)
    margin_px = _margin_px(margin_squares, margin_m, s, pps)
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
                  px_per_square: int = 100, margin_m: float | None = None) -> Board:
    """A ChArUco board drawn by ``cv2.aruco.CharucoBoard.generateImage``.

    ``squares_x`` x ``squares_y`` squares of side ``square_m`` with markers of side ``marker_m``
    in the white squares (OpenCV's current, non-legacy layout), a white margin of
    ``margin_squares`` squares (or ``margin_m`` metres when given). The margin and the marker
    side must come out as whole pixels.
    Truth: the (squares_x - 1) * (squares_y - 1) ChArUco corners with OpenCV's ids, and the
    marker corners and ids.
    """
    sx = _count("squares_x", squares_x, 2)
    sy = _count("squares_y", squares_y, 2)
    s = _positive("square_m", square_m)
    m = _positive("marker_m", marker_m)
    if m >= s:
        raise ValueError(f"marker_m ({m}) must be smaller than square_m ({s})")
    pps = _count("px_per_square", px_per_square, 2)
    margin_px = _margin_px(margin_squares, margin_m, s, pps)
    _whole_px("marker side (marker_m / square_m * px_per_square)", m / s * pps)
    d = _dictionary(dictionary)
    board = cv2.aruco.CharucoBoard((sx, sy), s, m, d)
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
                 margin_m=margin_m)


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
               px_per_marker: int = 100, first_id: int = 0) -> Board:
    """An ArUco grid drawn by ``cv2.aruco.GridBoard.generateImage``.

    ``markers_x`` x ``markers_y`` markers of side ``marker_m`` with gaps ``separation_m``, and a
    white margin ``margin_m`` (default: separation_m). Separation and margin must come out as
    whole pixels at ``px_per_marker``. Marker ids run row by row from ``first_id``. Truth
    points: every marker corner, id = marker_id * 4 + corner (OpenCV corner order TL, TR, BR, BL).
    """
    mx = _count("markers_x", markers_x, 1)
    my = _count("markers_y", markers_y, 1)
    m = _positive("marker_m", marker_m)
    sep = _positive("separation_m", separation_m)
    margin = sep if margin_m is None else float(margin_m)
    if not margin >= 0:
        raise ValueError(f"margin_m must be >= 0, got {margin_m!r}")
    ppx = _count("px_per_marker", px_per_marker, 8)
    ppm = ppx / m
    sep_px = _whole_px("separation (separation_m * px_per_marker / marker_m)", sep * ppm)
    margin_px = _whole_px("margin (margin_m * px_per_marker / marker_m)", margin * ppm)
    first = _count("first_id", first_id, 0)
    d = _dictionary(dictionary)
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

#: Candidate picture resolutions (pixels per square / per marker) tried by :func:`board_from_spec`,
#: best first: the first one that puts every length on whole pixels is used.
_SPEC_PX_CANDIDATES = tuple(range(100, 401)) + tuple(range(99, 31, -1))


def board_from_spec(target) -> Board:
    """Build the Board for a spec target (``scenegen.spec.model`` Checkerboard/Charuco/
    ArucoGridTarget, read by attribute so this module does not import the spec layer).

    The picture resolution is chosen here: the first pixels-per-square (or per-marker) in
    100..400, then 99..32, at which the margin, markers and separations are whole pixels; a
    ValueError names the target when there is none. The Board is in the BOARD frame (module
    docstring); the spec's object frame (centred, facing +z) is ``board.object_from_board()``.
    """
    kind = getattr(target, "kind", None)
    if kind == "checkerboard":
        def build(px):
            return checkerboard_board(target.inner_cols, target.inner_rows, target.square_m,
                                      px_per_square=px, margin_m=target.margin_m)
    elif kind == "charuco":
        def build(px):
            return charuco_board(target.squares_x, target.squares_y, target.square_m,
                                 target.marker_m, dictionary=target.dictionary,
                                 px_per_square=px, margin_m=target.margin_m)
    elif kind in ("aruco_grid", "aruco"):
        def build(px):
            return aruco_grid(target.markers_x, target.markers_y, target.marker_m,
                              target.separation_m, dictionary=target.dictionary,
                              margin_m=target.margin_m, px_per_marker=px,
                              first_id=getattr(target, "first_id", 0))
    else:
        raise ValueError(f"unknown calibration target kind {kind!r}")
    last = None
    for px in _SPEC_PX_CANDIDATES:
        try:
            return build(px)
        except ValueError as e:
            if "whole number of pixels" not in str(e):
                raise
            last = e
    raise ValueError(f"{kind} target: no picture resolution puts every length on whole pixels "
                     f"({last}); use lengths that are multiples of a common step")
