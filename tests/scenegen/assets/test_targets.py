"""Tests for scenegen.assets.targets: OpenCV's detectors, run on the board pictures, find the truth."""
from __future__ import annotations

import cv2
import numpy as np
import pytest

from scenegen.assets import targets
from scenegen.assets.board_raster import aruco_dictionary

# Detection on the clean, axis-aligned board picture (no rendering): the corners lie exactly on
# pixel edges, so cornerSubPix / the ChArUco interpolation land within hundredths of a pixel
# (measured <= 3e-5 px for ChArUco); 0.1 px is the project's acceptance threshold.
CORNER_TOL_PX = 0.1
# ArUco marker corners with CORNER_REFINE_SUBPIX: measured <= 0.086 px (the refinement sees the
# marker's own cell pattern near the corner); without refinement they are off by up to 0.5 px.
MARKER_TOL_PX = 0.15


def _subpix(img, corners):
    crit = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 100, 1e-4)
    return cv2.cornerSubPix(img, corners.astype(np.float32), (5, 5), (-1, -1), crit)


def _aruco_detector(dictionary):
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    return cv2.aruco.ArucoDetector(aruco_dictionary(dictionary), params)


class TestCheckerboard:
    @pytest.mark.parametrize("cols, rows", [(7, 5), (8, 6), (7, 6), (6, 7), (9, 6), (5, 5)])
    def test_find_chessboard_corners_order_and_position(self, cols, rows):
        b = targets.checkerboard_board(cols, rows, square_m=0.03, px_per_square=40)
        ok, found = cv2.findChessboardCorners(b.image, (cols, rows))
        assert ok
        found = _subpix(b.image, found).reshape(-1, 2)
        # Same order (point i <-> detection i) and same place.
        err = np.linalg.norm(found - b.points_image_px(), axis=1)
        assert err.max() < CORNER_TOL_PX

    def test_perspective_view_keeps_order_and_frame(self):
        """A supersampled perspective view of the picture (a stand-in for a render): detections
        still come in truth order and land on the homography-mapped truth.

        Resampling (bilinear warp at 4x, area downsampling) and cornerSubPix on foreshortened
        corners leave ~0.08 px mean / 0.12 px max error here (measured); a pixel-centre convention
        slip would bias every corner by ~0.35 px (half a board pixel at this scale), so the mean
        signed error is the sharp check.
        """
        b = targets.checkerboard_board(8, 6, 0.03, px_per_square=64)
        h, w = b.image.shape
        S = 4  # supersampling factor
        src = np.float32([[-0.5, -0.5], [w - 0.5, -0.5], [w - 0.5, h - 0.5], [-0.5, h - 0.5]])
        dst = np.float32([[80, 60], [560, 90], [530, 420], [110, 400]])  # picture edges, view px
        H = cv2.getPerspectiveTransform(src, (dst + 0.5) * S - 0.5)
        big = cv2.warpPerspective(b.image, H, (640 * S, 480 * S), flags=cv2.INTER_LINEAR,
                                  borderValue=128)
        view = cv2.resize(big, (640, 480), interpolation=cv2.INTER_AREA)
        ok, found = cv2.findChessboardCorners(view, (8, 6))
        assert ok
        found = _subpix(view, found).reshape(-1, 2)
        truth = (cv2.perspectiveTransform(b.points_image_px()[None], H)[0] + 0.5) / S - 0.5
        err = found - truth
        assert np.linalg.norm(err, axis=1).max() < 0.25
        assert np.linalg.norm(err.mean(axis=0)) < 0.03

    def test_frame_and_sizes(self):
        b = targets.checkerboard_board(4, 3, square_m=0.05, margin_squares=1, px_per_square=20)
        assert b.image.shape == (4 * 20 + 40, 5 * 20 + 40)
        assert b.size_m == pytest.approx((7 * 0.05, 6 * 0.05))
        assert b.px_per_m == pytest.approx(400.0)
        assert b.points_board.shape == (12, 3) and np.all(b.points_board[:, 2] == 0)
        # First corner: one margin square + one square from the top-left corner; x fastest.
        assert b.points_board[0] == pytest.approx([0.1, 0.1, 0])
        assert b.points_board[1] == pytest.approx([0.15, 0.1, 0])
        assert b.points_board[4] == pytest.approx([0.1, 0.15, 0])
        assert np.array_equal(b.point_ids, np.arange(12))
        assert b.image[20, 20] == 0 and b.image[0, 0] == 255  # top-left square black
        assert len(b.marker_ids) == 0 and b.marker_corners_board.shape == (0, 4, 3)

    def test_frozen_and_readonly(self):
        b = targets.checkerboard_board(4, 3, square_m=0.05)
        with pytest.raises(AttributeError):
            b.kind = "charuco"
        with pytest.raises(ValueError):
            b.points_board[0, 0] = 1.0

    def test_margin_must_be_whole_pixels(self):
        with pytest.raises(ValueError, match="whole number of pixels"):
            targets.checkerboard_board(4, 3, 0.05, margin_squares=0.3, px_per_square=25)


@pytest.mark.parametrize("size", [(7, 5), (6, 4)])  # odd and even rows (OpenCV's layouts differ)
class TestCharuco:
    @pytest.fixture(autouse=True)
    def _size(self, size):
        self.size = size

    def _board(self):
        return targets.charuco_board(*self.size, square_m=0.04, marker_m=0.03,
                                     dictionary="DICT_5X5_100", px_per_square=80)

    def test_truth_equals_cv2_object_points_in_our_frame(self):
        b = self._board()
        cvb = b.cv2_board()
        ours = b.points_board - [b.margin_m, b.margin_m, 0]
        assert np.allclose(ours, cvb.getChessboardCorners(), atol=1e-7)
        assert np.allclose(b.marker_corners_board - [b.margin_m, b.margin_m, 0],
                           np.asarray(cvb.getObjPoints()), atol=1e-7)
        assert np.array_equal(b.marker_ids, np.asarray(cvb.getIds()).ravel())
        assert len(b.point_ids) == (self.size[0] - 1) * (self.size[1] - 1)

    def test_charuco_detector_finds_truth(self):
        b = self._board()
        det = cv2.aruco.CharucoDetector(b.cv2_board())
        corners, ids, _, _ = det.detectBoard(b.image)
        assert ids is not None and len(ids) == len(b.point_ids)
        ids = ids.ravel()
        truth = dict(zip(b.point_ids, b.points_image_px()))
        err = np.linalg.norm(corners.reshape(-1, 2) - np.stack([truth[i] for i in ids]), axis=1)
        assert err.max() < CORNER_TOL_PX

    def test_marker_corners_detected(self):
        b = self._board()
        corners, ids, _ = _aruco_detector(b.dictionary).detectMarkers(b.image)
        assert sorted(ids.ravel()) == sorted(b.marker_ids)
        truth = dict(zip(b.marker_ids, b.marker_corners_image_px()))
        err = [np.abs(c.reshape(4, 2) - truth[i]).max() for c, i in zip(corners, ids.ravel())]
        assert max(err) < MARKER_TOL_PX

    def test_errors(self):
        with pytest.raises(ValueError, match="unknown ArUco dictionary 'DICT_NOPE'"):
            targets.charuco_board(5, 4, 0.04, 0.03, dictionary="DICT_NOPE")
        with pytest.raises(ValueError, match="marker_m"):
            targets.charuco_board(5, 4, 0.04, 0.05)
        with pytest.raises(ValueError, match="has 50 markers"):
            targets.charuco_board(12, 12, 0.04, 0.03, dictionary="DICT_4X4_50")


def test_legacy_charuco_layout_is_detected_by_a_legacy_board():
    """OpenCV's legacy layout (even squares_y: the top-left square white): our truth, the picture
    and cv2_board() agree, and a detector built without the legacy flag does not find it."""
    b = targets.charuco_board(6, 4, 0.04, 0.032, dictionary="DICT_5X5_100", px_per_square=100,
                              legacy_pattern=True)
    m = int(round(b.margin_m * b.px_per_m))
    assert b.image[m + 1, m + 1] == 255  # top-left square white (current layout: black)
    cvb = b.cv2_board()
    assert cvb.getLegacyPattern()
    assert np.allclose(b.marker_corners_board - [b.margin_m, b.margin_m, 0], np.asarray(cvb.getObjPoints()), atol=1e-7)
    corners, ids, _, _ = cv2.aruco.CharucoDetector(cvb).detectBoard(b.image)
    assert ids is not None and len(ids) == len(b.point_ids)
    truth = dict(zip(b.point_ids, b.points_image_px()))
    err = np.linalg.norm(corners.reshape(-1, 2) - np.stack([truth[i] for i in ids.ravel()]), axis=1)
    assert err.max() < CORNER_TOL_PX
    current = targets.charuco_board(6, 4, 0.04, 0.032, dictionary="DICT_5X5_100", px_per_square=100)
    assert current.image[m + 1, m + 1] == 0 and not np.array_equal(current.image, b.image)


class TestArucoGrid:
    def test_detector_finds_truth(self):
        b = targets.aruco_grid(4, 3, marker_m=0.04, separation_m=0.01, px_per_marker=80)
        assert b.image.shape == (3 * 80 + 2 * 20 + 2 * 20, 4 * 80 + 3 * 20 + 2 * 20)
        corners, ids, _ = _aruco_detector(b.dictionary).detectMarkers(b.image)
        assert sorted(ids.ravel()) == list(range(12))
        truth = dict(zip(b.point_ids, b.points_image_px()))
        for c, i in zip(corners, ids.ravel()):
            t = np.stack([truth[4 * i + k] for k in range(4)])
            assert np.abs(c.reshape(4, 2) - t).max() < MARKER_TOL_PX
        cvb = b.cv2_board()
        assert np.allclose(b.marker_corners_board - [b.margin_m, b.margin_m, 0],
                           np.asarray(cvb.getObjPoints()), atol=1e-7)

    def test_separation_must_be_whole_pixels(self):
        with pytest.raises(ValueError, match="separation.*whole number of pixels"):
            targets.aruco_grid(2, 2, marker_m=0.04, separation_m=0.0101, px_per_marker=100)


@pytest.mark.parametrize("make", [
    lambda: targets.checkerboard_board(5, 4, 0.03, px_per_square=30),
    lambda: targets.charuco_board(5, 4, 0.04, 0.03, px_per_square=64),
    lambda: targets.aruco_grid(3, 2, 0.04, 0.01, px_per_marker=40),
])
class TestMeshAndTexture:
    def test_mesh_covers_board_facing_minus_z(self, make):
        b = make()
        m = b.mesh()
        assert np.allclose(m.face_normals, [0, 0, -1])
        assert m.area == pytest.approx(b.width_m * b.height_m)
        assert np.allclose(m.bounds, [[0, 0, 0], [b.width_m, b.height_m, 0]])
        assert np.allclose(m.visual.uv, m.vertices[:, :2] / [b.width_m, b.height_m])

    def test_uv_maps_points_onto_their_pixels(self, make):
        """Each truth point's UV (interpolated on the mesh) lands on its image pixel coordinate."""
        b = make()
        m = b.mesh()
        # The mesh is affine in (x, y) -> uv; fit it from the vertices and apply to the points.
        A = np.c_[m.vertices[:, :2], np.ones(4)]
        coef, *_ = np.linalg.lstsq(A, m.visual.uv, rcond=None)
        uv = np.c_[b.points_board[:, :2], np.ones(len(b.points_board))] @ coef
        h, w = b.image.shape
        px = uv * [w, h] - 0.5  # texture (u, v) -> OpenCV pixel (u W - 0.5, v H - 0.5)
        assert np.allclose(px, b.points_image_px(), atol=1e-9)

    def test_texture_levels(self, make):
        b = make()
        t = b.texture(black=0.04, white=0.85)
        assert t.shape == b.image.shape + (3,) and t.dtype == np.float32
        assert np.allclose(np.unique(t[..., 0]), [0.04, 0.85])

    def test_describe_is_json_ready(self, make):
        import json

        d = make().describe()
        assert json.loads(json.dumps(d)) == d


def test_opencv_calibration_convention():
    """A camera on the board's -z side looking along +z sees the picture upright: projecting the
    truth points with cam_from_board = (I, t) keeps x right, y down and the image's orientation."""
    b = targets.checkerboard_board(6, 4, 0.05, px_per_square=40)
    K = np.array([[b.px_per_m, 0, -0.5], [0, b.px_per_m, -0.5], [0, 0, 1.0]])
    # Camera at depth 1 m with focal length px_per_m: maps the board 1:1 onto the picture.
    proj, _ = cv2.projectPoints(b.points_board, np.zeros(3), np.array([0, 0, 1.0]), K, None)
    assert np.allclose(proj.reshape(-1, 2), b.points_image_px(), atol=1e-9)
    # The camera centre is at board z = -1 (the -z side), where the mesh normal points.
    assert b.mesh().face_normals[0] @ np.array([0, 0, -1.0]) > 0


class TestSpecIntegration:
    def test_object_from_board_centres_and_faces_plus_z(self):
        b = targets.charuco_board(5, 4, 0.04, 0.03, px_per_square=64)
        T = b.object_from_board()
        mesh = b.mesh()
        v_obj = T.apply(mesh.vertices)
        assert np.allclose(v_obj.mean(axis=0), 0)
        n_obj = mesh.face_normals @ T.R.T
        assert np.allclose(n_obj, [0, 0, 1])
        # Upright seen from +z with +y up: the picture's top-left corner is at (-w/2, +h/2).
        assert np.allclose(T.apply(np.zeros((1, 3))), [[-b.width_m / 2, b.height_m / 2, 0]])
        # The same placement as shapes.plane: identical (position, uv) pairs.
        from scenegen.assets import shapes

        plane = shapes.plane((b.width_m, b.height_m))
        key = lambda v, uv: sorted(map(tuple, np.round(np.c_[v, uv], 9)))  # noqa: E731
        assert key(v_obj, mesh.visual.uv) == key(plane.vertices, plane.visual.uv)

    def test_board_from_spec_dataclasses(self):
        from scenegen.spec import model as m

        cb = targets.board_from_spec(m.CheckerboardTarget(inner_cols=6, inner_rows=4,
                                                          square_m=0.03, margin_m=0.0123))
        assert cb.kind == "checkerboard" and cb.margin_m == pytest.approx(0.0123)
        ok, found = cv2.findChessboardCorners(cb.image, (6, 4))
        assert ok and np.abs(_subpix(cb.image, found).reshape(-1, 2)
                             - cb.points_image_px()).max() < CORNER_TOL_PX
        ch = targets.board_from_spec(m.CharucoTarget(squares_x=5, squares_y=4, square_m=0.04,
                                                     marker_m=0.03, dictionary="DICT_4X4_50",
                                                     margin_m=0.04))
        assert ch.kind == "charuco" and ch.margin_m == pytest.approx(0.04)
        ar = targets.board_from_spec(m.ArucoGridTarget(markers_x=3, markers_y=2, marker_m=0.05,
                                                       separation_m=0.01, dictionary="DICT_4X4_50",
                                                       margin_m=0.01, first_id=7))
        assert ar.kind == "aruco" and list(ar.marker_ids) == list(range(7, 13))
        corners, ids, _ = _aruco_detector("DICT_4X4_50").detectMarkers(ar.image)
        assert sorted(ids.ravel()) == list(range(7, 13))
        truth = dict(zip(ar.marker_ids, ar.marker_corners_image_px()))
        assert max(np.abs(c.reshape(4, 2) - truth[i]).max()
                   for c, i in zip(corners, ids.ravel())) < MARKER_TOL_PX
        assert np.array_equal(np.asarray(ar.cv2_board().getIds()).ravel(), ar.marker_ids)

    def test_board_from_spec_rejects_irrational_lengths(self):
        from types import SimpleNamespace

        t = SimpleNamespace(kind="checkerboard", inner_cols=4, inner_rows=3, square_m=0.03,
                            margin_m=0.03 / np.pi)
        with pytest.raises(ValueError, match="checkerboard target: no picture resolution"):
            targets.board_from_spec(t)
        with pytest.raises(ValueError, match="unknown calibration target kind"):
            targets.board_from_spec(SimpleNamespace(kind="circles"))
