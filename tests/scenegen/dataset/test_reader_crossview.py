"""The typed reader of a rendered dataset's cross-view truth agrees with its files."""
import numpy as np
import pytest

from scenegen.dataset import Dataset, DatasetError
from scenegen.dataset import codecs as sio
from scenegen.dataset.crossview import MATCH_COLUMNS, VISIBLE, decode_correspondence_channels
from scenegen.geometry.twoview import undistorted_pixels

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def ds(crossview_render):
    return Dataset(crossview_render[1])


def test_dataset_repr_len_and_views(ds):
    assert len(ds) == len(ds.views) == 5 and "5 of 5 views complete" in repr(ds)
    assert ds.views[0] in ds and "nope" not in ds
    assert ds.scene_name == "crossview_test" and ds.object_id("ball") == 3
    assert ds.rig_partners("st_left_0000") == ("st_right_0000",) and ds.rig_partners("side_0002") == ()
    assert ds.target_names == ("board",) and ds.target("board")["kind"] == "checkerboard"
    with pytest.raises(KeyError, match="not in this dataset"):
        ds.image("nope")


def test_index_is_typed(ds):
    idx = ds.crossview.index
    assert idx.pairs == (("st_left_0000", "st_right_0000"), ("st_left_0000", "st_left_0001"),
                         ("st_left_0000", "side_0002"))
    assert idx.stereo == (("st_left_0000", "st_right_0000"), ("st_left_0001", "st_right_0001"))
    assert len(ds.crossview) == 3 and "3 pairs" in repr(idx) and idx.occlusion_rel_tol == 1e-4


def test_correspondence_and_matches_equal_the_files(ds):
    i, j = "st_left_0000", "side_0002"
    c = ds.crossview.correspondence(i, j)
    raw = decode_correspondence_channels(sio.read_exr(ds.path(f"crossview/corr/{i}/{j}.exr")))
    assert np.array_equal(c.state, raw.state) and np.array_equal(c.uv, raw.uv, equal_nan=True)
    assert c.visible.sum() == (c.state == VISIBLE).sum() > 0 and len(c) == c.state.size
    m = ds.crossview.matches(i, j, "synthetic")
    rows = sio.read_npy(ds.path(f"crossview/matches/{i}/{j}_synthetic.npy"))
    assert np.array_equal(m.rows, rows) and np.array_equal(m.column("error_px"), rows[:, MATCH_COLUMNS.index("error_px")])
    assert m.inliers.sum() == (rows[:, 6] == 0).sum() and len(m) == len(rows)


def test_twoview_and_stereo_typed(ds):
    tv = ds.crossview.twoview("st_left_0000", "st_right_0000")
    raw = sio.read_json(ds.path("crossview/twoview/st_left_0000/st_right_0000.json"))
    assert np.array_equal(tv.F, np.array(raw["F"])) and tv.baseline_m == pytest.approx(raw["baseline_m"])
    fr = ds.crossview.stereo("st_left_0000")
    assert fr.right_view == "st_right_0000" and fr.camera.model == "pinhole"
    d = fr.disparity("left")
    kd, ok = fr.disparity_kitti("left", "noc")
    assert np.array_equal(ok, fr.correspondence("left").visible)
    assert np.abs(kd[ok] - d[ok]).max() <= 0.5 / 256 + 1e-6
    assert fr.rectification_map("left").shape == d.shape + (2,)


def test_missing_truth_is_named(ds):
    with pytest.raises(DatasetError, match=r"crossview/corr/st_right_0000/side_0002\.exr"):
        ds.crossview.correspondence("st_right_0000", "side_0002")
    with pytest.raises(KeyError, match="no rectified stereo frame"):
        ds.crossview.stereo("side_0002")


def test_stereo_frames_without_pairs():
    """An index with stereo frames and no pairs (a stereo rig, crossview.pairs: none) still lists
    its frames: the index is not 'empty' because it has no pairs."""
    from scenegen.dataset.crossview_reader import CrossviewTruth

    doc = {"format": "scenegen-crossview", "format_version": 1, "occlusion_rel_tol": 1e-4, "pairs": [], "flow": [],
           "stereo": [{"left_view": "l0", "right_view": "r0", "dir": "crossview/stereo/l0"}], "targets": []}

    class Fake:
        def has(self, rel):
            return True

        def read(self, rel, reader, what):
            return doc

    cv = CrossviewTruth(Fake())
    assert len(cv) == 0 and [(f.left_view, f.right_view) for f in cv.stereo_frames()] == [("l0", "r0")]


def test_fundamental_stored_or_from_cameras(ds):
    """The stored F where the dataset has one; else K2^-T [t]x R K1^-1 of cameras.json, checked here
    against the dataset's own visible correspondences (read in the pair's other direction)."""
    i, j = "st_left_0000", "side_0002"
    F, source = ds.crossview.fundamental(i, j)
    assert source == f"crossview/twoview/{i}/{j}.json" and np.array_equal(F, ds.crossview.twoview(i, j).F)
    assert not ds.has(f"crossview/twoview/{j}/{i}.json")
    F_ji, source = ds.crossview.fundamental(j, i)
    assert source == "cameras.json: K2^-T [t]x R K1^-1"
    c = ds.crossview.correspondence(i, j)
    vv, uu = np.nonzero(c.visible)
    und_i = undistorted_pixels(ds.camera(i)[0], np.stack([uu, vv], 1))  # F is for undistorted pixels
    und_j = undistorted_pixels(ds.camera(j)[0], c.uv[vv, uu])
    x_i, x_j = (np.concatenate([x, np.ones((len(x), 1))], 1) for x in (und_i, und_j))
    lines = x_j @ F_ji.T  # epipolar lines in view i of view j's points
    dist_px = np.abs(np.sum(lines * x_i, 1)) / np.hypot(lines[:, 0], lines[:, 1])
    assert len(dist_px) > 100 and dist_px.max() < 1e-2


def test_pair_flow_is_the_held_flow_truth(ds):
    i, j = "st_left_0000", "side_0002"  # a crossview pair: correspondences, no flow file
    flow, states, source = ds.crossview.pair_flow(i, j)
    c = ds.crossview.correspondence(i, j)
    H, W = c.shape
    np.testing.assert_array_equal(flow[..., 0], c.uv[..., 0] - np.arange(W)[None, :])
    np.testing.assert_array_equal(flow[..., 1], c.uv[..., 1] - np.arange(H)[:, None])
    assert np.array_equal(states, c.state) and source == f"crossview/corr/{i}/{j}.exr (uv - pixel)"
    for a, b in ds.crossview.index.flow:
        flow, _, source = ds.crossview.pair_flow(a, b)
        assert source == f"crossview/flow/{a}/{b}.flo" and np.array_equal(flow, ds.crossview.flow(a, b), equal_nan=True)
    assert ds.crossview.pair_flow("st_right_0000", "side_0002") is None
