"""Flow files, match sets, board truth and the dataset layout of the cross-view outputs."""
import struct

import cv2
import numpy as np
import pytest

from scenegen.crossview.matches import MatchParams, synthetic_matches
from scenegen.dataset import Dataset, codecs as sio, verify
from scenegen.dataset.codecs import (
    decode_pfm,
    disparity_from_kitti_array as decode_kitti,
    encode_pfm,
    kitti_disparity_array as encode_kitti,
)
from scenegen.dataset.codecs.flo import decode_flo, encode_flo
from scenegen.dataset.crossview import (
    INLIER,
    NEAR_MISS_OUTLIER,
    NO_TRUTH,
    OCCLUDED,
    UNIFORM_OUTLIER,
    VISIBLE,
    WRONG,
    decode_correspondence_channels,
)

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def ds(crossview_render):
    return Dataset(crossview_render[1])


def _read_flo_independently(path):
    """Middlebury's C reader, transcribed: float tag, int width, int height, then (u, v) floats."""
    with open(path, "rb") as f:
        tag, = struct.unpack("<f", f.read(4))
        w, h = struct.unpack("<ii", f.read(8))
        data = np.frombuffer(f.read(), "<f4")
    assert tag == 202021.25 and data.size == w * h * 2
    return data.reshape(h, w, 2)


def test_flow_files_match_correspondences(ds):
    idx = sio.read_json(ds.path("crossview/index.json"))
    assert {(f["i"], f["j"]) for f in idx["flow"]} == {("st_left_0000", "st_left_0001"),
                                                       ("st_right_0000", "st_right_0001")}
    f = _read_flo_independently(ds.path("crossview/flow/st_left_0000/st_left_0001.flo"))
    c = decode_correspondence_channels(sio.read_exr(ds.path("crossview/corr/st_left_0000/st_left_0001.exr")))
    H, W = c.state.shape
    known = np.abs(f[..., 0]) < 1e9
    assert np.array_equal(known, np.isfinite(c.uv[..., 0]))
    grid_u = np.arange(W)[None, :].repeat(H, 0)
    assert np.abs(f[..., 0][known] - (c.uv[..., 0][known] - grid_u[known])).max() < 1e-4
    # the backward flow exists too
    assert ds.path("crossview/flow/st_left_0001/st_left_0000.flo").is_file()


def test_flo_pfm_kitti_round_trip():
    rng = np.random.default_rng(0)
    flow = rng.normal(0, 20, (7, 9, 2))
    flow[2, 3] = np.nan
    back = decode_flo(encode_flo(flow))
    assert np.isnan(back[2, 3]).all() and np.allclose(back[np.isfinite(back)], flow[np.isfinite(flow)].astype(np.float32))
    d = rng.uniform(0, 100, (5, 6))
    d[0, 0] = np.inf
    data = encode_pfm(d)
    assert data.startswith(b"Pf\n6 5\n-1.0\n")
    # Middlebury: the first stored row is the BOTTOM row, little-endian float32
    first_row = np.frombuffer(data[len(b"Pf\n6 5\n-1.0\n"):], "<f4")[:6]
    assert np.array_equal(first_row, d[-1].astype(np.float32))
    assert np.array_equal(decode_pfm(data), d.astype(np.float32))
    k = encode_kitti(d, np.isfinite(d))
    assert k.dtype == np.uint16 and k[0, 0] == 0
    dd, ok = decode_kitti(sio.decode_png(sio.encode_png(k)))
    assert np.abs(dd[ok] - d[ok]).max() <= 0.5 / 256 and not ok[0, 0]


def test_synthetic_matches_labels_and_noise():
    H, W = 60, 80
    uv = np.stack(np.meshgrid(np.arange(W) + 3.25, np.arange(H) - 1.5), -1)
    vis = np.ones((H, W), bool)
    p = MatchParams(count=4000, sigma_px=0.7, outlier_fraction=0.3, near_miss_fraction=0.5,
                    near_miss_px=(4.0, 10.0), seed=5)
    rows = synthetic_matches(uv, vis, W, H, p)
    assert rows.shape == (4000, 8)
    lab = rows[:, 6]
    assert (lab == INLIER).sum() == 2800 and (lab == NEAR_MISS_OUTLIER).sum() == 600
    assert (lab == UNIFORM_OUTLIER).sum() == 600
    inl = rows[lab == INLIER]
    # truth columns are the exact field at the true pixel (pixel centre = round of the noisy one
    # is not assumed); noise on j is N(0, sigma^2) per axis: sum of squares / sigma^2 ~ chi2(2 n)
    dj = (inl[:, 2:4] - inl[:, 4:6]).ravel() / p.sigma_px
    assert abs(np.mean(dj ** 2) - 1.0) < 0.06  # 5 sigma of chi2 with 5600 dof / 5600
    near = rows[lab == NEAR_MISS_OUTLIER]
    assert (near[:, 7] >= 4.0).all() and (near[:, 7] <= 10.0).all()
    assert (rows[lab == UNIFORM_OUTLIER][:, 7] >= 4.0).all()
    assert np.array_equal(synthetic_matches(uv, vis, W, H, p), rows)  # seeded


def test_stored_match_sets(ds):
    idx = sio.read_json(ds.path("crossview/index.json"))
    for p in idx["pairs"]:
        i, j = p["i"], p["j"]
        syn = sio.read_npy(ds.path(f"crossview/matches/{i}/{j}_synthetic.npy"))
        c = decode_correspondence_channels(sio.read_exr(ds.path(f"crossview/corr/{i}/{j}.exr")))
        assert len(syn) == 400 and (syn[:, 6] == INLIER).sum() == 300
        # the truth column is the stored correspondence of a visible pixel near the observed one
        inl = syn[syn[:, 6] == INLIER]
        H, W = c.state.shape
        ui, vi = np.clip(np.rint(inl[:, 0]), 0, W - 1).astype(int), np.clip(np.rint(inl[:, 1]), 0, H - 1).astype(int)
        near_truth = np.hypot(*(c.uv[vi, ui] - inl[:, 4:6]).T)
        assert np.median(near_truth) < 3.0
        sift = sio.read_npy(ds.path(f"crossview/matches/{i}/{j}_sift.npy"))
        lab = sift[:, 6]
        assert set(np.unique(lab)) <= {INLIER, WRONG, NO_TRUTH}
        assert (sift[lab == INLIER, 7] <= 2.0).all() and (sift[lab == WRONG, 7] > 2.0).all()
        assert np.isinf(sift[lab == NO_TRUTH, 7]).all()
        assert (lab == INLIER).mean() > 0.5, (i, j, np.bincount(lab.astype(int)))
        # independent check of SIFT truth: for keypoints that are inliers, the dense field at the
        # nearest pixel is within ~1 px (the field varies by < 1 px per pixel here)
        kin = sift[lab == INLIER]
        ui, vi = np.clip(np.rint(kin[:, 0]), 0, W - 1).astype(int), np.clip(np.rint(kin[:, 1]), 0, H - 1).astype(int)
        ok = c.visible[vi, ui]
        assert np.median(np.hypot(*(c.uv[vi, ui][ok] - kin[ok, 4:6]).T)) < 1.0


def test_board_truth_per_view(ds):
    for v in ds.views:
        t = sio.read_json(ds.path(f"crossview/targets/{v}.json"))["boards"]["board"]
        cam, pose = ds.camera(v)
        P = np.array(t["points_world"])
        uv = np.array([x if x is not None else [np.nan, np.nan] for x in t["uv"]])
        assert np.allclose(uv, cam.project(pose.apply(P)), atol=1e-9, equal_nan=True)
        assert all(t["facing"]) and t["state"].count(VISIBLE) == len(P)
    # OpenCV finds the corners where the truth says they are (render blur: sub-pixel agreement)
    v = "st_left_0000"
    t = sio.read_json(ds.path(f"crossview/targets/{v}.json"))["boards"]["board"]
    grey = cv2.cvtColor(ds.image(v), cv2.COLOR_RGB2GRAY)
    found, corners = cv2.findChessboardCorners(grey, (5, 4))
    assert found
    corners = cv2.cornerSubPix(grey, corners, (3, 3), (-1, -1),
                               (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4)).reshape(-1, 2)
    truth = np.array(t["uv"])
    err = np.min(np.linalg.norm(corners[:, None] - truth[None], axis=2), axis=1)
    print(f"findChessboardCorners + cornerSubPix vs truth: median {np.median(err):.3f} px, max {err.max():.3f} px")
    assert np.median(err) < 0.3


def test_layout_is_hashed_and_verifies(ds):
    assert verify(ds.root).ok
    files = set(ds.manifest["files"])
    idx = sio.read_json(ds.path("crossview/index.json"))
    assert set(idx["files"]) <= files and "crossview/index.json" in files
    assert idx["occlusion_rel_tol"] == 1e-4
    c = sio.read_exr(ds.path("crossview/corr/st_left_0000/side_0002.exr"))
    assert c["u"].dtype == np.float32 and c["state"].dtype == np.uint32


def test_spec_section_and_pair_selection(tmp_path):
    from scenegen.pipeline.pairs import consecutive_pairs, select_pairs
    from scenegen.spec import parse_spec, resolve_views

    text = ("cameras:\n  cam: {size: [64, 48], fov_deg: 60}\n"
            "rigs:\n  st: {type: stereo, left: cam, right: cam, baseline_m: 0.1}\n"
            "views:\n  - camera: cam\n    orbit: {radius_m: 2, count: 3}\n"
            "  - rig: st\n    orbit: {radius_m: 2, count: 2}\n")
    assert parse_spec(text, base_dir=tmp_path).crossview is None  # no section: no cross-view files
    spec = parse_spec(text + "crossview: {}\n", base_dir=tmp_path)
    cv = spec.crossview
    assert (cv.pairs, cv.flow, cv.stereo, cv.matches, cv.sift, cv.targets) == ("consecutive", True, True, None, False, True)
    views = resolve_views(spec)
    assert consecutive_pairs(views) == [
        ("cam_0000", "cam_0001"), ("cam_0001", "cam_0002"), ("st_left_0003", "st_right_0003"),
        ("st_left_0003", "st_left_0004"), ("st_right_0003", "st_right_0004"), ("st_left_0004", "st_right_0004")]
    assert len(select_pairs("all", views)) == 7 * 6 // 2 and select_pairs("none", views) == []
    spec = parse_spec(text + "crossview:\n  pairs: [[cam_0000, st_right_0004]]\n  matches: {count: 5}\n",
                      base_dir=tmp_path)
    assert spec.crossview.pairs == (("cam_0000", "st_right_0004"),) and spec.crossview.matches.count == 5


TINY_STEREO = """
render: {spp: 4, max_depth: 2}
objects:
  - {name: wall, shape: {type: plane, size: [4, 4]}, transform: {translation: [0, 2, 0], rotation_deg: [90, 0, 0]}}
  - {name: ball, shape: {type: sphere, radius: 0.2}, transform: {translation: [0, 1, 0]}}
lights: [{type: constant, radiance: 1.0}]
cameras:
  cam: {size: [64, 48], fov_deg: 60}
rigs:
  st: {type: stereo, left: cam, right: cam, baseline_m: 0.1}
views:
  - rig: st
    path: {line: {from: [-0.1, -1, 0], to: [0.1, -1, 0]}, count: 2, target: [0, 2, 0]}
crossview: {matches: {count: 20}}
"""


def test_partial_runs_then_resume_equal_one_full_run(tmp_path):
    """--frames 0 then --resume writes the same bytes (every hash in the manifest) as one run;
    the partial run writes no index."""
    from scenegen.pipeline.run import render_spec

    spec = tmp_path / "tiny.yaml"
    spec.write_text(TINY_STEREO)
    render_spec(spec, tmp_path / "a", frames="0", progress=False)
    assert not (tmp_path / "a/crossview/index.json").exists()
    assert (tmp_path / "a/crossview/stereo/st_left_0000/disp_left.pfm").is_file()
    render_spec(spec, tmp_path / "a", resume=True, progress=False)
    render_spec(spec, tmp_path / "b", progress=False)
    ma, mb = Dataset(tmp_path / "a").manifest, Dataset(tmp_path / "b").manifest
    assert ma["files"] == mb["files"] and "crossview/index.json" in ma["files"]
    assert verify(tmp_path / "a").ok


def test_board_truth_charuco_markers_and_back_side():
    """numpy-only: a ChArUco board seen from its printed side, then from behind."""
    from scenegen.assets.targets import charuco_board
    from scenegen.crossview.targets import board_view_truth
    from scenegen.geometry.camera import Camera
    from scenegen.geometry.pose import Rigid3

    board = charuco_board(5, 4, 0.04, 0.03, px_per_square=24)  # markers 3 px into their squares
    cam = Camera("opencv", 320, 240, 300.0, 300.0, 159.5, 119.5, 0.0, (-0.1, 0.01, 0, 0))
    # the print faces the board's -z: a camera at z = -0.5 looking along +z sees it upright
    cam_from_board = Rigid3(np.eye(3), [-board.width_m / 2, -board.height_m / 2, 0.5])
    world_from_board = Rigid3.identity()
    t = board_view_truth(board, world_from_board, cam, cam_from_board, lambda C, X: np.ones(len(X), bool))
    assert t["state"] == [VISIBLE] * len(board.point_ids) and all(t["facing"])
    M = len(board.marker_ids)
    assert t["marker_ids"] == board.marker_ids.tolist() and len(t["marker_corners"]["uv"]) == M
    uv = np.array(t["marker_corners"]["uv"]).reshape(-1, 2)
    assert np.allclose(uv, cam.project(cam_from_board.apply(board.marker_corners_board.reshape(-1, 3))), atol=1e-12)
    behind = Rigid3(np.diag([-1.0, 1.0, -1.0]), [board.width_m / 2, -board.height_m / 2, 0.5])  # from +z
    t = board_view_truth(board, world_from_board, cam, behind, lambda C, X: np.ones(len(X), bool))
    assert not any(t["facing"]) and set(t["state"]) == {OCCLUDED}
