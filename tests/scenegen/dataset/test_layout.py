"""The dataset layout: names that become paths are checked, paths are the documented ones."""
import pytest

from scenegen.dataset import layout


@pytest.mark.parametrize("name", ["", ".hidden", "a/b", "..", "a b", "x" * 129, "é", None])
def test_bad_names_are_refused(name):
    with pytest.raises(ValueError, match="name"):
        layout.check_name("object", name)


@pytest.mark.parametrize("view", ["a_ids", "a_linear", "a_valid", "a_vignetting", "a_raw"])
def test_view_names_may_not_collide_with_suffixed_files(view):
    with pytest.raises(ValueError, match="collide"):
        layout.view_paths(view)


@pytest.mark.parametrize("rel", ["/abs", "a/../b", "a\\b", ".x/y", "a//b", "manifest.json"])
def test_bad_relative_paths_are_refused(rel):
    with pytest.raises(ValueError):
        layout.check_rel_path(rel)


def test_documented_paths():
    assert layout.view_paths("cam_0001") == {
        "image": "images/cam_0001.png", "linear": "images/cam_0001_linear.exr", "truth": "truth/cam_0001.exr",
        "ids": "truth/cam_0001_ids.exr", "valid": "truth/cam_0001_valid.png"}
    assert layout.vignetting_path("v") == "truth/v_vignetting.exr"
    assert layout.raw_dng_path("v") == "raw/v.dng"
    assert layout.raw_png_path("v") == "images/v_raw.png"
    assert layout.mesh_path("ball") == "scene/meshes/ball.ply"
    assert layout.target_path("board") == "scene/targets/board.json"
    assert layout.correspondence_path("a", "b") == "crossview/corr/a/b.exr"
    assert layout.flow_path("a", "b") == "crossview/flow/a/b.flo"
    assert layout.twoview_path("a", "b") == "crossview/twoview/a/b.json"
    assert layout.matches_path("a", "b", "sift") == "crossview/matches/a/b_sift.npy"
    assert layout.view_targets_path("a") == "crossview/targets/a.json"
    assert layout.stereo_path("l", "disparity_noc", "right") == "crossview/stereo/l/disp_right_noc.png"
    assert layout.stereo_path("l", "calib") == "crossview/stereo/l/calib.json"
    with pytest.raises(ValueError, match="match kind"):
        layout.matches_path("a", "b", "orb")
    with pytest.raises(ValueError, match="stereo file"):
        layout.stereo_path("l", "image", "middle")
    with pytest.raises(ValueError, match="name"):
        layout.correspondence_path("a", "../b")


def test_names_under():
    files = ["scene/meshes/a.ply", "scene/meshes/b.ply", "scene/meshes/x/c.ply", "scene/targets/t.json"]
    assert layout.names_under(files, layout.MESHES_DIR, ".ply") == ("a", "b")
