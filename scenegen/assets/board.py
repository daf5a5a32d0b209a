"""The calibration board record: its printed picture and exact 3D truth (no Mitsuba).

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

How the picture's resolution is chosen so that it is exactly the stored board:
:mod:`scenegen.assets.board_raster`; the builders: :mod:`scenegen.assets.targets`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
import trimesh

from scenegen.assets.board_raster import aruco_dictionary
from scenegen.geometry.pose import Rigid3

BoardKind = str  # 'checkerboard' | 'charuco' | 'aruco'
BOARD_KINDS = ("checkerboard", "charuco", "aruco")


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
        legacy_pattern: ChArUco only: OpenCV's legacy layout (before 4.6), whose chessboard
            starts with a white square when squares_y is even (the same board when it is odd).
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
    legacy_pattern: bool = False

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
            board = cv2.aruco.CharucoBoard(self.grid, self.square_m, self.marker_m,
                                           aruco_dictionary(self.dictionary))
            board.setLegacyPattern(bool(self.legacy_pattern))
            return board
        if self.kind == "aruco":
            return cv2.aruco.GridBoard(self.grid, self.marker_m, self.separation_m,
                                       aruco_dictionary(self.dictionary),
                                       np.asarray(self.marker_ids, dtype=np.int32))
        raise ValueError("a checkerboard has no cv2.aruco board object")

    def describe(self) -> dict:
        """The board's parameters as a JSON-ready dict (no image, no points); ``legacy_pattern``
        only when set."""
        d = {"kind": self.kind, "size_m": [self.width_m, self.height_m],
             "px_per_m": self.px_per_m, "grid": list(self.grid), "square_m": self.square_m,
             "marker_m": self.marker_m, "separation_m": self.separation_m,
             "margin_m": self.margin_m, "dictionary": self.dictionary,
             "num_points": int(len(self.point_ids)), "num_markers": int(len(self.marker_ids))}
        if self.legacy_pattern:
            d["legacy_pattern"] = True
        return d
