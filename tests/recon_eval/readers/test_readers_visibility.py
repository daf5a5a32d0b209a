"""One visibility truth: a point of view 1 is seen by view 2 when the dataset's ray-cast state in
``crossview/corr/<view1>/<view2>.exr`` says VISIBLE, never by a depth test of the evaluator's own.

The occluded plane dataset (conftest.py) plants the case where they disagree: a wire thinner than
a pixel hangs between the rig and the plane, missing every pixel centre's ray of both cameras (the
depth maps show only the plane) but blocking the ray from each camera to one column of the other's
truth points. The former 1 % depth test at view 2's nearest pixel centre called those points
visible; the states call them occluded, and every caller of the correspondences follows the states."""
import json

import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.errors import NotApplicable
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.tasks.triangulation_task import build_pair
from scenegen.dataset.crossview import OCCLUDED, VISIBLE

#: The relative depth tolerance of the depth test recon_eval used before (readers/scenegen_dataset.py).
OLD_DEPTH_REL_TOL = 0.01


def depth_test_visible(ds, view1, view2, x1, X):
    """The former visibility rule, for comparison: depth in view 2 within 1 % of the truth depth at
    view 2's nearest pixel centre (and inside the image)."""
    cam2, pose2 = ds.camera(view2)
    Xc = pose2.apply(X)
    x2, ok = cam2.project(Xc, return_valid=True)
    ok &= (x2[:, 0] > -0.5) & (x2[:, 0] < cam2.width - 0.5) & (x2[:, 1] > -0.5) & (x2[:, 1] < cam2.height - 0.5)
    d2 = ds.depth(view2)
    vi = np.clip(np.rint(x2[:, 1]), 0, cam2.height - 1).astype(int)
    ui = np.clip(np.rint(x2[:, 0]), 0, cam2.width - 1).astype(int)
    return ok & (np.abs(Xc[:, 2] - d2[vi, ui]) <= OLD_DEPTH_REL_TOL * d2[vi, ui])


@pytest.mark.parametrize("view1, view2", [("left_000", "right_000"), ("right_000", "left_000")])
def test_the_ray_cast_states_decide_not_a_depth_test(occluded_plane_dataset, plane_scene, view1, view2):
    ds = read_dataset(occluded_plane_dataset[0])
    n_all = plane_scene.W * plane_scene.H
    state = ds.correspondence(view1, view2).state
    wire = plane_scene.WIRE_COLUMN
    assert np.all(state[:, wire] == OCCLUDED) and not np.any(np.delete(state, wire, axis=1) == OCCLUDED)
    # the depth maps never see the wire: the plane's depth (3 m) at every pixel
    assert np.allclose(ds.depth(view2), plane_scene.HEIGHT_M, rtol=1e-6)
    x1_all, X = ds.points_at_pixels(view1, max_points=n_all)
    old = depth_test_visible(ds, view1, view2, x1_all, X)
    on_wire = x1_all[:, 0] == wire
    assert on_wire.sum() == plane_scene.H and np.all(old[on_wire])  # the depth test called them visible
    x1, x2 = ds.correspondences(view1, view2, max_points=n_all)
    assert not np.any(x1[:, 0] == wire)  # the states call them occluded: dropped
    # every other decision agrees: the kept pixels are the depth test's minus the occluded column
    kept = {tuple(p) for p in x1}
    assert kept == {tuple(p) for p in x1_all[old & ~on_wire]}
    assert len(x1) == int(np.sum(state == VISIBLE))
    # and x2 is the projection of the stored truth point, as before
    cam2, pose2 = ds.camera(view2)
    sel = np.isin(x1_all[:, 1] * 1000 + x1_all[:, 0], x1[:, 1] * 1000 + x1[:, 0])
    np.testing.assert_array_equal(x2, cam2.project(pose2.apply(X[sel])))


def test_sampled_correspondences_keep_the_seeded_pixel_sample(occluded_plane_dataset):
    ds = read_dataset(occluded_plane_dataset[0])
    x1_all, _ = ds.points_at_pixels("left_000", max_points=300, seed=3)
    x1, _ = ds.correspondences("left_000", "right_000", max_points=300, seed=3)
    assert {tuple(p) for p in x1} <= {tuple(p) for p in x1_all} and 0 < len(x1) < len(x1_all)


def test_every_caller_follows_the_states(occluded_plane_dataset, plane_scene, tmp_path, capsys):
    root, cams = occluded_plane_dataset
    ds = read_dataset(root)
    x1, _ = ds.correspondences("left_000", "right_000", max_points=10_000)
    # triangulation tasks: the occluded column's points are not truth points of the pair
    tp = build_pair(ds, "left_000", "right_000", 0.0, count=10_000)
    assert len(tp.points_true) == len(x1)
    np.testing.assert_allclose(tp.observations[:, :2], x1, atol=1e-6)
    # recon-eval fmatrix --dataset: the truth correspondences are the visible ones
    np.savetxt(tmp_path / "F.txt", np.array([[0.0, 0, 0], [0, 0, -1], [0, 1, 0]]))
    assert main(["fmatrix", str(tmp_path / "F.txt"), "--dataset", str(root), "--views", "left_000", "right_000",
                 "--json", str(tmp_path / "f.json"), "--quiet"]) == 0
    doc = json.loads((tmp_path / "f.json").read_text())
    assert doc["results"]["fundamental"]["n_points"] == len(x1)
    assert doc["results"]["fundamental"]["sampson_rms_px"] < 1e-4  # rectified: rows agree


def test_a_pair_without_correspondence_truth_is_one_clear_error(write_plane, tmp_path, capsys):
    root = tmp_path / "ds"
    write_plane(root, views=("left_000", "right_000"), corr_pairs=[("right_000", "left_000")])
    with pytest.raises(NotApplicable) as e:
        read_dataset(root).correspondences("left_000", "right_000")
    msg = str(e.value)
    assert "crossview/corr/left_000/right_000.exr: no such file" in msg and "crossview.pairs" in msg
    assert "\n" not in msg
    np.savetxt(tmp_path / "F.txt", np.eye(3))
    for argv in (["fmatrix", tmp_path / "F.txt", "--dataset", root, "--views", "left_000", "right_000"],
                 ["triangulation-task", root, "-o", tmp_path / "t", "--pairs", "left_000:right_000"]):
        assert main([str(a) for a in argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "left_000/right_000.exr: no such file" in err and "Traceback" not in err
    assert read_dataset(root).correspondences("right_000", "left_000")[0].shape[1] == 2  # the other way is there
