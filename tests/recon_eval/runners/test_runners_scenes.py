"""End-to-end runs of real estimators on the bundled scenes (issue 7): render once per session
through scenegen (never inside recon_eval), run, score, gate. Each threshold is the issue's
requirement; the gate file gates/opencv.yaml is the project's own and is checked here."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.render  # renders the library scenes

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "scenes"
#: Samples per pixel of the test renders: the scene's own 16 (corner accuracy depends on edge
#: anti-aliasing; at spp 4 the orbit_sfm rotation error measured 0.56 deg, at 16 0.17 deg) except the
#: noisy calibration scene, whose sensor noise dominates at any spp. (These figures were measured
#: asking for 8, which Mitsuba's ldsampler rounds up to 16: the same images.)
SPP = {"calib_checkerboard": 16, "calib_checkerboard_noisy": 4, "stereo_tabletop": 16, "wide_baseline": 16,
       "orbit_sfm": 16}


@pytest.fixture(scope="session")
def datasets(tmp_path_factory):
    from scenegen.pipeline.run import render_spec

    root = tmp_path_factory.mktemp("library")
    out = {}
    for name, spp in SPP.items():
        render_spec(SCENES / f"{name}.yaml", root / name, spp=spp, progress=False)
        out[name] = root / name
    return out


@pytest.fixture(scope="session")
def results(datasets, tmp_path_factory):
    from recon_eval.runners import run_method

    root = tmp_path_factory.mktemp("runs")
    plan = [("calib_checkerboard", "opencv-calib-checkerboard"), ("calib_checkerboard", "broken-calib-cx"),
            ("calib_checkerboard_noisy", "opencv-calib-checkerboard"), ("stereo_tabletop", "opencv-stereo-sgbm"),
            ("wide_baseline", "opencv-f-ransac"), ("wide_baseline", "opencv-f-8point"),
            ("wide_baseline", "broken-f-transposed"), ("orbit_sfm", "pycolmap-incremental"),
            ("wide_baseline", "opencv-f-7point"), ("wide_baseline", "survey-f-seven-point"),
            ("wide_baseline", "survey-f-cfns"), ("wide_baseline", "survey-f-mlesac")]
    out = {}
    for scene, m in plan:
        run_method(m, datasets[scene], root / scene / m)
        out[(scene, m)] = root / scene / m / "result.json"
    return out


def _metrics(results, scene, method):
    return json.loads(results[(scene, method)].read_text())["metrics"]


def test_checkerboard_calibration_recovers_intrinsics(results):
    m = _metrics(results, "calib_checkerboard", "opencv-calib-checkerboard")
    assert m["views_used_ratio"] == 1.0
    assert m["fx_rel_err"] <= 0.002 and m["fy_rel_err"] <= 0.002  # issue 7: 0.2 %
    assert m["cx_abs_err_px"] <= 0.5 and m["cy_abs_err_px"] <= 0.5  # issue 7: 0.5 px
    assert m["proj_diff_rms_px"] <= 0.1  # issue 7: distortion field within 0.1 px RMS


def test_calibration_raw_output_is_opencv_yaml(results):
    import cv2

    p = results[("calib_checkerboard", "opencv-calib-checkerboard")].parent / "calibration_cam.yaml"
    fs = cv2.FileStorage(str(p), cv2.FILE_STORAGE_READ)
    assert fs.getNode("camera_matrix").mat().shape == (3, 3)
    assert fs.getNode("distortion_coefficients").mat().size == 5
    fs.release()


def test_noise_makes_calibration_worse_and_is_reported(results):
    clean = _metrics(results, "calib_checkerboard", "opencv-calib-checkerboard")
    noisy = _metrics(results, "calib_checkerboard_noisy", "opencv-calib-checkerboard")
    assert noisy["calib_rms_px"] > 1.5 * clean["calib_rms_px"]  # detections are noisier
    assert noisy["proj_diff_rms_px"] > 2 * clean["proj_diff_rms_px"]  # and so is the recovered model


def test_sgbm_bias_and_bad2_reported(results):
    m = _metrics(results, "stereo_tabletop", "opencv-stereo-sgbm")
    assert 0.0 <= m["bad_2_0_noc_pct"] < 100.0
    assert abs(m["median_signed_err_px"]) <= 0.25  # issue 7: disparity bias within 0.25 px
    pfm = results[("stereo_tabletop", "opencv-stereo-sgbm")].parent / "disparity"
    assert len(list(pfm.glob("*.pfm"))) == 1


def test_fundamental_ransac_recall_and_8point_sampson(results):
    r = _metrics(results, "wide_baseline", "opencv-f-ransac")
    assert r["synthetic.inlier_recall"] > 0.8  # issue 7, 30 % outliers, sigma 0.5 px
    e = _metrics(results, "wide_baseline", "opencv-f-8point")
    assert e["synthetic.sampson_rms_px"] <= 2 * 0.5  # within 2 x the noise sigma


def test_survey_estimators_run_on_the_wide_baseline_scene(results):
    """Issue 34: the survey's methods as runners. The 7-point method is fed the same seven labelled
    inliers as OpenCV's and writes the same F; CFNS on the labelled inliers is within the noise;
    MLESAC finds the inliers among 30 % outliers."""
    import numpy as np

    ours = results[("wide_baseline", "survey-f-seven-point")].parent / "pair_0000__pair_0001/synthetic_F.txt"
    theirs = results[("wide_baseline", "opencv-f-7point")].parent / "pair_0000__pair_0001/synthetic_F.txt"
    a, b = np.loadtxt(ours), np.loadtxt(theirs)
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    assert min(np.linalg.norm(a - b), np.linalg.norm(a + b)) <= 1e-6  # measured 2.9e-8 (OpenCV: unnormalised pixels)
    assert _metrics(results, "wide_baseline", "survey-f-cfns")["synthetic.sampson_rms_px"] <= 2 * 0.5
    m = _metrics(results, "wide_baseline", "survey-f-mlesac")
    assert m["synthetic.inlier_recall"] > 0.8 and m["synthetic.sampson_rms_px"] <= 2 * 0.5


def test_pycolmap_registers_every_image(results):
    m = _metrics(results, "orbit_sfm", "pycolmap-incremental")
    assert m["registration_ratio"] == 1.0
    assert m["max_rot_err_deg"] < 0.5


def test_pycolmap_runs_are_reproducible(datasets, results, tmp_path):
    """A second run gives the same model bit for bit (threads and seeds fixed; before, the max
    rotation error on orbit_sfm varied by ~1e-3 deg from run to run)."""
    from recon_eval.runners import run_method

    first = results[("orbit_sfm", "pycolmap-incremental")].parent
    doc = run_method("pycolmap-incremental", datasets["orbit_sfm"], tmp_path / "again")
    assert doc["metrics"] == _metrics(results, "orbit_sfm", "pycolmap-incremental")
    for f in ("cameras.bin", "images.bin", "points3D.bin"):
        assert (tmp_path / "again" / "colmap" / "sparse" / f).read_bytes() == (first / "colmap" / "sparse" / f).read_bytes()
    assert (results[("orbit_sfm", "pycolmap-incremental")].parent / "colmap" / "sparse" / "images.bin").is_file()


def _gate(*args):
    return subprocess.run([sys.executable, "-m", "recon_eval", "gate", *map(str, args)], capture_output=True,
                          text=True, cwd=ROOT)


def test_project_gate_file_holds_on_project_data(results, tmp_path):
    good = [p for (s, m), p in results.items() if not m.startswith("broken") and s != "calib_checkerboard_noisy"]
    r = _gate(ROOT / "gates" / "opencv.yaml", *good, "--junit", tmp_path / "j.xml")
    assert r.returncode == 0, r.stdout + r.stderr
    assert 'failures="0"' in (tmp_path / "j.xml").read_text()


@pytest.mark.parametrize("broken, good, scene, metric", [
    ("broken-calib-cx", "opencv-calib-checkerboard", "calib_checkerboard", "cx_abs_err_px"),
    ("broken-f-transposed", "opencv-f-8point", "wide_baseline", "synthetic.sampson_rms_px"),
])
def test_broken_estimator_fails_its_gate_naming_the_metric(results, tmp_path, broken, good, scene, metric):
    import yaml

    gates = yaml.safe_load((ROOT / "gates" / "opencv.yaml").read_text())["gates"]
    g = next(x for x in gates if x["method"] == good and x["metric"] == metric)
    f = tmp_path / "g.yaml"
    f.write_text(yaml.safe_dump({"version": 1, "gates": [{**g, "method": broken}]}))
    r = _gate(f, results[(scene, broken)], "--junit", tmp_path / "j.xml")
    assert r.returncode == 1
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("FAIL"))
    assert metric in line and f"{g['threshold']:g}" in line
    assert 'failures="1"' in (tmp_path / "j.xml").read_text()


def test_baseline_mode_fails_on_worsening(results, tmp_path):
    import yaml

    f = tmp_path / "g.yaml"
    f.write_text(yaml.safe_dump({"version": 1, "gates": [
        {"scene": "calib_checkerboard", "method": "opencv-calib-checkerboard", "metric": "cx_abs_err_px",
         "op": "<=", "threshold": 5.0}]}))
    good = results[("calib_checkerboard", "opencv-calib-checkerboard")]
    doc = json.loads(results[("calib_checkerboard", "broken-calib-cx")].read_text())
    doc["inputs"]["method"] = "opencv-calib-checkerboard"  # the same method, now 2 px worse
    worse = tmp_path / "worse.json"
    worse.write_text(json.dumps(doc))
    assert _gate(f, good, "--baseline", good, "--margin", "0.1").returncode == 0
    r = _gate(f, worse, "--baseline", good, "--margin", "0.1", "--margin-abs", "0.05")
    assert r.returncode == 1 and "baseline" in r.stdout and "cx_abs_err_px" in r.stdout


def test_leaderboard_writes_three_formats(datasets, tmp_path):
    r = subprocess.run([sys.executable, "-m", "recon_eval", "leaderboard", "--datasets", str(datasets["wide_baseline"]),
                        str(datasets["stereo_tabletop"]), "--methods", "opencv-f-usac-magsac", "opencv-stereo-bm",
                        "-o", str(tmp_path)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "leaderboard.json").read_text())
    assert {(x["inputs"]["scene"], x["inputs"]["method"]) for x in doc["runs"]} == {
        ("wide_baseline", "opencv-f-usac-magsac"), ("stereo_tabletop", "opencv-stereo-bm")}
    assert len(doc["skipped"]) == 2  # stereo on a pair without a rig, F on a rig without matches
    assert "| `wide_baseline` | `opencv-f-usac-magsac` |" in (tmp_path / "leaderboard.md").read_text()
    assert "<table>" in (tmp_path / "leaderboard.html").read_text()
