"""Scoring commands find the truth themselves from the dataset and a view/pair name (issue 15):
`fmatrix --dataset` on a distorted pair uses the truth F for undistorted pixels and says which
pixels it takes (`--pixels`), keeps the pose error, and scores an inlier mask; `disparity --view`
on a stereo dataset of distorted cameras scores against the rectified frame's truth;
`calibration` picks the calibrated camera or says why it cannot."""
import json

import cv2
import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.readers.scenegen_dataset import read_dataset
from scenegen.geometry.twoview import fundamental


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def _sampson_rms(F, x1, x2):
    """Sampson RMS from scratch (H&Z eq. 11.9)."""
    h1, h2 = np.c_[x1, np.ones(len(x1))], np.c_[x2, np.ones(len(x2))]
    Fx1, Ftx2 = h1 @ F.T, h2 @ F
    num = np.sum(h2 * Fx1, axis=1) ** 2
    den = Fx1[:, 0] ** 2 + Fx1[:, 1] ** 2 + Ftx2[:, 0] ** 2 + Ftx2[:, 1] ** 2
    return float(np.sqrt(np.mean(num / den)))


def _cv_undistort(cam, x):
    K = cam.K
    D = np.asarray(cam.dist, float)
    return cv2.undistortPointsIter(x.reshape(-1, 1, 2), K, D, None, K,
                                   (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-12)).reshape(-1, 2)


class TestFmatrixDistortedPair:
    VIEWS = ("free_000", "left_000")  # free_000: OpenCV camera with distortion

    def _truth_F(self, cams):
        (c1, p1), (c2, p2) = cams[self.VIEWS[0]], cams[self.VIEWS[1]]
        return fundamental(c1.K, c2.K, p2 @ p1.inverse())

    def test_undistorted_pixels_score_the_truth_F_perfectly(self, plane_dataset, tmp_path, capsys):
        root, cams = plane_dataset
        np.savetxt(tmp_path / "F.txt", self._truth_F(cams))
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--dataset", root, "--views", *self.VIEWS,
                            "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        doc = json.loads((tmp_path / "r.json").read_text())
        r = doc["results"]
        assert doc["inputs"]["pixels"] == "undistorted" and "undistorted pixels" in doc["inputs"]["f_gt"]
        assert r["fundamental"]["sampson_rms_px"] < 1e-4 and r["zhang_f_distance"]["f_distance_px"] < 1e-9
        assert r["pose_via_K"]["pose_err_deg"] < 1e-3  # kept on a distorted pair

    def test_sampson_agrees_with_opencv_undistortion(self, plane_dataset, tmp_path, capsys):
        """A perturbed F: the reported RMS equals a from-scratch Sampson on the truth correspondences
        undistorted by OpenCV (an independent inverse of the distortion)."""
        root, cams = plane_dataset
        F = self._truth_F(cams)
        U, sv, Vt = np.linalg.svd(F + 1e-3 * np.abs(F).max() * np.random.default_rng(3).normal(size=(3, 3)))
        F = U @ np.diag([sv[0], sv[1], 0.0]) @ Vt  # a rank-2 F near the truth
        np.savetxt(tmp_path / "F.txt", F)
        assert run(["fmatrix", tmp_path / "F.txt", "--dataset", root, "--views", *self.VIEWS, "--json",
                    tmp_path / "r.json", "--quiet"], capsys)[0] == 0
        got = json.loads((tmp_path / "r.json").read_text())["results"]["fundamental"]["sampson_rms_px"]
        ds = read_dataset(root)
        x1, x2 = ds.correspondences(*self.VIEWS)
        F_read = np.loadtxt(tmp_path / "F.txt")
        ref = _sampson_rms(F_read, _cv_undistort(cams[self.VIEWS[0]][0], x1), _cv_undistort(cams[self.VIEWS[1]][0], x2))
        assert got > 0.05 and got == pytest.approx(ref, rel=1e-6)

    def test_distorted_pixels_say_there_is_no_truth_F(self, plane_dataset, tmp_path, capsys):
        root, cams = plane_dataset
        np.savetxt(tmp_path / "F.txt", self._truth_F(cams))
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--dataset", root, "--views", *self.VIEWS,
                            "--pixels", "distorted", "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        doc = json.loads((tmp_path / "r.json").read_text())
        assert doc["inputs"]["pixels"] == "distorted" and doc["inputs"]["f_gt"].startswith("none: the cameras have")
        r = doc["results"]
        assert "zhang_f_distance" not in r and "pose_via_K" in r
        ds = read_dataset(root)
        x1, x2 = ds.correspondences(*self.VIEWS)
        assert r["fundamental"]["sampson_rms_px"] == pytest.approx(_sampson_rms(self._truth_F(cams), x1, x2), rel=1e-9)
        assert r["fundamental"]["sampson_rms_px"] > 0.05  # the distortion the truth F does not model

    def test_pinhole_pair_is_the_same_in_both_pixels(self, plane_dataset, tmp_path, capsys):
        root, cams = plane_dataset
        (c1, p1), (c2, p2) = cams["left_000"], cams["right_000"]
        np.savetxt(tmp_path / "F.txt", fundamental(c1.K, c2.K, p2 @ p1.inverse()) + 1e-4)
        res = []
        for px in ("undistorted", "distorted"):
            assert run(["fmatrix", tmp_path / "F.txt", "--dataset", root, "--views", "left_000", "right_000",
                        "--pixels", px, "--json", tmp_path / f"{px}.json", "--quiet"], capsys)[0] == 0
            res.append(json.loads((tmp_path / f"{px}.json").read_text())["results"])
        assert res[0] == res[1]


def test_own_matches_need_no_correspondence_truth(plane_dataset, write_plane, tmp_path, capsys):
    """--matches with --dataset: the dataset gives F, K and pose; its correspondence files are not needed."""
    root, cams = plane_dataset
    bare = tmp_path / "bare"
    write_plane(bare, corr_pairs=[])
    x1, x2 = read_dataset(root).correspondences("left_000", "right_000")
    np.save(tmp_path / "m.npy", np.c_[x1, x2])
    (c1, p1), (c2, p2) = cams["left_000"], cams["right_000"]
    np.savetxt(tmp_path / "F.txt", fundamental(c1.K, c2.K, p2 @ p1.inverse()))
    code, _, err = run(["fmatrix", tmp_path / "F.txt", "--dataset", bare, "--views", "left_000", "right_000",
                        "--matches", tmp_path / "m.npy", "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    r = json.loads((tmp_path / "r.json").read_text())["results"]
    assert r["fundamental"]["n_points"] == len(x1) and r["fundamental"]["sampson_rms_px"] < 1e-4
    code, _, err = run(["fmatrix", tmp_path / "F.txt", "--dataset", bare, "--views", "left_000", "right_000"], capsys)
    assert code == 2 and "no correspondence truth" in err


class TestInlierMask:
    def test_precision_recall_of_a_mask_against_labels(self, tmp_path, capsys):
        rng = np.random.default_rng(0)
        m = rng.uniform(0, 60, (40, 4))
        labels = np.arange(40) < 30  # 30 truth inliers
        mask = labels.copy()
        mask[:5] = False  # 5 inliers missed
        mask[30:32] = True  # 2 outliers taken
        np.save(tmp_path / "m.npy", m)
        np.save(tmp_path / "labels.npy", labels)
        (tmp_path / "mask.txt").write_text("\n".join(str(int(v)) for v in mask))
        np.savetxt(tmp_path / "F.txt", np.array([[0, 0, 0], [0, 0, -1], [0, 1, 0.0]]))
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--matches", tmp_path / "m.npy", "--inliers",
                            tmp_path / "mask.txt", "--labels", tmp_path / "labels.npy", "--json", tmp_path / "r.json",
                            "--quiet"], capsys)
        assert code == 0, err
        inl = json.loads((tmp_path / "r.json").read_text())["results"]["inliers"]
        assert inl["precision"] == pytest.approx(25 / 27, abs=1e-15) and inl["recall"] == pytest.approx(25 / 30, abs=1e-15)

    def test_mask_errors(self, plane_dataset, tmp_path, capsys):
        np.savetxt(tmp_path / "F.txt", np.eye(3))
        np.save(tmp_path / "m.npy", np.ones((4, 4)))
        np.save(tmp_path / "k.npy", np.ones(3, bool))
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--matches", tmp_path / "m.npy", "--inliers",
                            tmp_path / "k.npy"], capsys)
        assert code == 2 and "--inliers needs the truth labels" in err
        np.save(tmp_path / "two.npy", np.full(4, 2.0))
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--matches", tmp_path / "m.npy", "--inliers",
                            tmp_path / "k.npy", "--labels", tmp_path / "two.npy"], capsys)
        assert code == 2 and "two.npy: a mask holds 0/1" in err
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--matches", tmp_path / "m.npy", "--inliers",
                            tmp_path / "k.npy", "--labels", tmp_path / "k.npy"], capsys)
        assert code == 2 and "k.npy: 3 mask values for 4 rows" in err
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--dataset", plane_dataset[0], "--views", "left_000",
                            "right_000", "--match-set", "synthetic", "--inliers", tmp_path / "k.npy"], capsys)
        assert code == 2 and "have no 'synthetic' match set" in err


class TestCalibrationCamera:
    def test_several_cameras_need_a_name(self, plane_dataset, tmp_path, capsys):
        from recon_eval.readers.opencv_calib import write_opencv_calibration

        root, cams = plane_dataset
        write_opencv_calibration(tmp_path / "c.yaml", cams["free_000"][0])
        code, _, err = run(["calibration", tmp_path / "c.yaml", root], capsys)
        assert code == 2 and "different cameras (left, right, free): pass --camera NAME" in err
        code, _, err = run(["calibration", tmp_path / "c.yaml", root, "--camera", "free", "--json", tmp_path / "r.json",
                            "--quiet"], capsys)
        assert code == 0, err
        doc = json.loads((tmp_path / "r.json").read_text())
        assert doc["inputs"]["view"] == "free_000" and doc["results"]["intrinsics"]["fx_abs_err_px"] == 0
        code, _, err = run(["calibration", tmp_path / "c.yaml", root, "--camera", "nope"], capsys)
        assert code == 2 and "no view of camera 'nope'" in err


# --- disparity on a stereo rig of distorted cameras: the rectified truth ----------------------------
@pytest.fixture(scope="module")
def stereo_rig(tmp_path_factory):
    from pathlib import Path

    from scenegen.pipeline.run import render_spec

    root = Path(__file__).resolve().parents[3]
    text = (root / "scenes" / "stereo_tabletop.yaml").read_text()
    text = text.replace("size: [400, 300]", "size: [160, 120]").replace("fx: 330", "fx: 132").replace(
        "fy: 330", "fy: 132").replace("spp: 16", "spp: 4")
    spec = tmp_path_factory.mktemp("rig") / "rig.yaml"
    spec.write_text(text)
    render_spec(spec, spec.parent / "ds", progress=False)
    return spec.parent / "ds"


@pytest.mark.render
def test_disparity_view_uses_the_rectified_truth(stereo_rig, tmp_path, capsys):
    from scenegen.dataset.codecs import write_pfm

    ds = read_dataset(stereo_rig)
    (left,) = ds.stereo_left_views()
    gt, noc = ds.stereo_disparity(left), ds.stereo_noc_mask(left)
    ok = np.flatnonzero((noc & np.isfinite(gt)).ravel())
    est = gt.copy()
    est.ravel()[ok[::50][:10]] += 3.0  # 10 non-occluded pixels 3 px off
    write_pfm(tmp_path / "d.pfm", est)
    code, _, err = run(["disparity", tmp_path / "d.pfm", stereo_rig, "--view", left, "--benchmark", "middlebury",
                        "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "r.json").read_text())
    assert doc["inputs"]["gt_kind"].endswith(f"crossview/stereo/{left}") and "non-occlusion" in doc["inputs"]["gt_noc"]
    assert doc["inputs"]["scene"] == "stereo_tabletop"
    assert doc["results"]["middlebury"]["bad_2_0_pct"] == pytest.approx(100 * 10 / len(ok), abs=1e-12)
    code, _, err = run(["disparity", tmp_path / "d.pfm", stereo_rig, "--view", left, "--truth", "view"], capsys)
    assert code == 2 and "two identical pinhole cameras" in err


@pytest.mark.render
def test_disparity_command_agrees_with_the_stereo_run(stereo_rig, tmp_path, capsys):
    """The SGBM run's own PFM scored by `disparity --view` (the rectified truth, found from the view
    name alone) gives the run's non-occluded bad-2.0 and avgerr."""
    from recon_eval.runners import run_method

    doc = run_method("opencv-stereo-sgbm", stereo_rig, tmp_path / "run")
    (pfm,) = doc["inputs"]["raw_files"]
    left = pfm.removeprefix("disparity/").removesuffix(".pfm")
    code, _, err = run(["disparity", tmp_path / "run" / pfm, stereo_rig, "--view", left, "--benchmark", "middlebury",
                        "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    mb = json.loads((tmp_path / "r.json").read_text())["results"]["middlebury"]
    assert mb["bad_2_0_pct"] == pytest.approx(doc["metrics"]["bad_2_0_noc_pct"], abs=1e-12)
    assert mb["avgerr_px"] == pytest.approx(doc["metrics"]["avgerr_noc_px"], abs=1e-12)
