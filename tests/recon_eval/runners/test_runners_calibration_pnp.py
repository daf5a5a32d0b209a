"""End-to-end runs on the rest of the issue-7 scene library: ChArUco and fisheye calibration, and
solvePnP / solvePnPRansac on board corners and on noisy 2D-3D truth with outliers. Rendered once
per session through scenegen (never inside recon_eval). Each tolerance is named below with the
figure it was set from (measured at the fixture's spp; docs/ci.md lists the methods)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "scenes"
#: Samples per pixel of the test renders. ChArUco at the scene's own 16 (at 4 the cy error measured
#: 0.35 px against 0.27 px at 16, too close to the 0.5 px bound; measured asking for 8, which the
#: ldsampler rounds up to 16); the fisheye and marker scenes at 4.
SPP = {"calib_charuco": 16, "calib_fisheye": 4, "markers_poster": 4}

pytestmark = pytest.mark.render  # renders the scenes it scores

#: issue 7's intrinsics bounds (stated for the checkerboard), held by ChArUco and fisheye too.
FOCAL_REL_TOL = 0.002  # 0.2 %
PRINCIPAL_POINT_TOL_PX = 0.5
#: ChArUco projection-difference RMS bound. Measured 0.34 px (max 1.6 px): most of it is the
#: principal-point error (cy 0.27 px), which the 16 poses x 48 corners at ~0.07 px detection noise
#: do not pin down better (a Gaussian-noise simulation of the same poses gives 0.2-0.3 px). The
#: checkerboard's 0.1 px is NOT reached with this board; the bound catches a regression to the
#: folding / 0.6 px models that OpenCV's default ChArUco detection gave before the runner's fixes.
CHARUCO_PROJ_DIFF_RMS_PX = 0.5
#: Fisheye projection-difference RMS bound over the whole 480x480 image (to ~81 deg off axis;
#: the board corners reach ~60 deg). Measured 0.14 px (max 1.4 px in the image corners).
FISHEYE_PROJ_DIFF_RMS_PX = 0.25
#: solvePnP (iterative) on ChArUco corners with the truth intrinsics: measured median 0.018 deg
#: and 0.076 px reprojection RMS (cornerSubPix-level corners).
CHARUCO_PNP_ROT_DEG = 0.1
CHARUCO_PNP_REPROJ_PX = 0.15
#: solvePnP on ArUco-grid marker corners (OpenCV's default detector, no corner refinement) at ~1 m:
#: measured 0.82 deg and 0.90 px. The detector's corners sit ~0.5-0.7 px inside the true marker
#: outline (measured against the board truth, independent of marker size), which is what these
#: figures show; a regression of the detection or of the id -> corner matching gives tens of px.
MARKER_PNP_ROT_DEG = 1.5
MARKER_PNP_REPROJ_PX = 1.5
#: solvePnPRansac (SQPnP) on 200 truth 2D-3D points per view, sigma 1 px, 30 % outliers: measured
#: median 0.11 deg, 1.3 mm at ~1.2 m.
RANSAC_POINTS_ROT_DEG = 0.5
RANSAC_POINTS_TRANS_M = 0.005


@pytest.fixture(scope="session")
def more_datasets(tmp_path_factory):
    from scenegen.pipeline.run import render_spec

    root = tmp_path_factory.mktemp("library_more")
    out = {}
    for name, spp in SPP.items():
        render_spec(SCENES / f"{name}.yaml", root / name, spp=spp, progress=False)
        out[name] = root / name
    return out


@pytest.fixture(scope="session")
def more_results(more_datasets, tmp_path_factory):
    from recon_eval.runners import run_method

    root = tmp_path_factory.mktemp("runs_more")
    plan = [("calib_charuco", "opencv-calib-charuco"), ("calib_fisheye", "opencv-calib-fisheye"),
            ("calib_charuco", "opencv-pnp-iterative"), ("markers_poster", "opencv-pnp-iterative"),
            ("markers_poster", "opencv-pnp-ransac-sqpnp")]
    out = {}
    for scene, m in plan:
        run_method(m, more_datasets[scene], root / scene / m)
        out[(scene, m)] = root / scene / m / "result.json"
    return out


def _metrics(results, scene, method):
    return json.loads(results[(scene, method)].read_text())["metrics"]


@pytest.mark.parametrize("scene, method, proj_diff_tol", [
    ("calib_charuco", "opencv-calib-charuco", CHARUCO_PROJ_DIFF_RMS_PX),
    ("calib_fisheye", "opencv-calib-fisheye", FISHEYE_PROJ_DIFF_RMS_PX),
])
def test_calibration_recovers_intrinsics(more_results, scene, method, proj_diff_tol):
    m = _metrics(more_results, scene, method)
    assert m["views_used_ratio"] == 1.0
    assert m["fx_rel_err"] <= FOCAL_REL_TOL and m["fy_rel_err"] <= FOCAL_REL_TOL, m
    assert m["cx_abs_err_px"] <= PRINCIPAL_POINT_TOL_PX and m["cy_abs_err_px"] <= PRINCIPAL_POINT_TOL_PX, m
    assert m["proj_diff_rms_px"] <= proj_diff_tol, m


def test_fisheye_raw_output_is_equidistant_yaml(more_results):
    import cv2

    p = more_results[("calib_fisheye", "opencv-calib-fisheye")].parent / "calibration_cam.yaml"
    fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_READ)
    assert fs.getNode("distortion_model").string() == "equidistant"
    assert fs.getNode("distortion_coefficients").mat().size == 4
    fs.release()


def test_calibration_runners_refuse_the_wrong_camera_or_board(more_datasets, tmp_path):
    from recon_eval.runners import NotApplicable, run_method

    with pytest.raises(NotApplicable, match="no OpenCV/pinhole camera sees"):  # a checkerboard, but a fisheye camera
        run_method("opencv-calib-checkerboard", more_datasets["calib_fisheye"], tmp_path / "a")
    with pytest.raises(NotApplicable, match="has no charuco board"):  # ArUco grid only
        run_method("opencv-calib-charuco", more_datasets["markers_poster"], tmp_path / "b")


@pytest.mark.parametrize("scene, rot_tol, reproj_tol, views", [
    ("calib_charuco", CHARUCO_PNP_ROT_DEG, CHARUCO_PNP_REPROJ_PX, 16),
    ("markers_poster", MARKER_PNP_ROT_DEG, MARKER_PNP_REPROJ_PX, 6),
])
def test_solvepnp_on_board_corners(more_results, scene, rot_tol, reproj_tol, views):
    doc = json.loads(more_results[(scene, "opencv-pnp-iterative")].read_text())
    m = doc["metrics"]
    assert doc["inputs"]["notes"]["target_views"] == views  # the board was found in every view
    assert m["targets.failure_ratio"] == 0.0
    assert m["targets.median_rot_err_deg"] <= rot_tol, m
    assert m["targets.median_reproj_rms_px"] <= reproj_tol, m


def test_solvepnp_ransac_on_noisy_truth_with_outliers(more_results):
    r = _metrics(more_results, "markers_poster", "opencv-pnp-ransac-sqpnp")
    assert r["points.failure_ratio"] == 0.0
    assert r["points.median_rot_err_deg"] <= RANSAC_POINTS_ROT_DEG, r
    assert r["points.median_trans_err_m"] <= RANSAC_POINTS_TRANS_M, r
    # the same points without RANSAC: 30 % outliers break the plain least-squares solve
    plain = _metrics(more_results, "markers_poster", "opencv-pnp-iterative")
    assert plain["points.median_rot_err_deg"] > 10 * r["points.median_rot_err_deg"], plain


def test_pnp_raw_output_lists_every_view(more_results):
    raw = json.loads((more_results[("markers_poster", "opencv-pnp-ransac-sqpnp")].parent / "poses.json").read_text())
    assert sorted(raw["points"]) == [f"hand_{i:04d}" for i in range(6)]
    assert all(v is not None and len(v["rvec"]) == 3 for v in raw["targets"].values())


# --- zero-baseline pairs (a roll about the optical axis, an illumination pair) ----------------
def test_f_and_e_runners_skip_zero_baseline_pairs(tmp_path, zero_baseline_spec):
    """The rolled view shares the reference's centre: its twoview truth has no F or E
    (crossview.md), so the F and E runners skip it with a note and score the other pair."""
    from scenegen.pipeline.run import render_spec
    from recon_eval.runners import run_method
    from recon_eval.runners.twoview import ZERO_BASELINE_NOTE


    (tmp_path / "zb.yaml").write_text(zero_baseline_spec)
    render_spec(tmp_path / "zb.yaml", tmp_path / "ds", progress=False)
    tv = json.loads((tmp_path / "ds" / "crossview" / "twoview" / "cam_0000" / "cam_0001.json").read_text())
    assert tv["F"] is None and tv["E"] is None and tv["baseline_m"] < 1e-9
    for method in ("opencv-f-8point", "opencv-e-usac-magsac"):
        doc = run_method(method, tmp_path / "ds", tmp_path / method)
        assert doc["inputs"]["notes"]["cam_0000__cam_0001"] == ZERO_BASELINE_NOTE
        assert not any("cam_0000__cam_0001" in k for k in doc["results"])
        assert any(k.startswith("cam_0000__cam_0002.synthetic") for k in doc["results"])
        assert all(f.startswith("cam_0000__cam_0002/") for f in doc["inputs"]["raw_files"])
