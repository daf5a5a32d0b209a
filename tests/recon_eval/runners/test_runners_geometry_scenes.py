"""The issue-9 scenes rendered and scored end to end: the DLT on the 3D calibration object
(scenes/dlt_calibration_object.yaml, at its own settings) and triangulation over the baseline-angle
series (scenes/triangulation_baselines.yaml at half resolution, same field of view). Rendered once
per session through scenegen (never inside recon_eval). Each bound names the figure it was set
from (measured at these settings)."""
from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from recon_eval.cli import main

pytestmark = pytest.mark.render  # renders the scenes it scores

SCENES = Path(__file__).resolve().parents[3] / "scenes"
#: The triangulation scene at half size (240x180, fx 210: the same field of view) and 4 spp: the
#: truth, not the image, is what the triangulation task uses.
TRI_FULL = "cam: {model: pinhole, size: [480, 360], fx: 420}"
TRI_SMALL = "cam: {model: pinhole, size: [240, 180], fx: 210}"
TRI_SPP = 4

#: Linear DLT (no refinement) on the detected ArUco corners of the three boards (~180 per view):
#: measured median over the 8 views fx 1.0 % relative, rotation 0.22 deg, camera centre 6.8 mm at
#: ~0.9 m, held-out reprojection RMS 0.18 px. OpenCV's default ArUco corners sit ~0.5-0.7 px inside
#: the true marker outline (runners/test_runners_calibration_pnp.py), which shrinks the object and so biases the
#: focal length; the bounds leave ~3x. A wrong id -> corner match gives tens of px and degrees.
DLT_TARGETS_FOCAL_REL = 0.03
DLT_TARGETS_ROT_DEG = 0.75
DLT_TARGETS_CENTER_M = 0.02
DLT_TARGETS_REPROJ_PX = 0.5
#: Linear DLT on 200 truth points per view with sigma = 1 px noise: measured fx 0.87 %, rotation
#: 0.40 deg, reprojection RMS 0.23 px (median over views).
DLT_POINTS_FOCAL_REL = 0.03
DLT_POINTS_ROT_DEG = 1.2
DLT_POINTS_REPROJ_PX = 0.6
#: Detected corners against the exact per-view corner truth (crossview/targets/<view>.json, an
#: independent source: the scene's boards projected by scenegen): measured median 0.83 px, 95th
#: percentile 1.4 px (the detector's inward bias above). A wrong id or corner order moves a corner
#: by at least one marker side (~20 px here).
DETECTION_MEDIAN_PX = 2.0
#: The marker outlines of the rendered image against the corner truth, with no detector: the
#: 50 % crossing of the linear intensity across each outer marker edge, sampled at the edge's
#: midpoint along its normal. Bilinear sampling of a box-filtered step puts the crossing up to
#: ~0.08 px off the edge depending on the sub-pixel phase, which the median over ~800 edges
#: averages out: measured median +0.01 px. The OpenCV detector's inward bias (~0.8 px above) or a
#: half-pixel convention error would read as -0.5 px or more.
OUTLINE_MEDIAN_PX = 0.05
#: Edges shorter than this (px) are skipped: the profile (+-PROFILE_PX) must stay inside the
#: marker's black border cell (1/6 of a 4x4 marker's side) and the white separation around it.
OUTLINE_MIN_SIDE_PX = 24.0
OUTLINE_PROFILE_PX = 3.0
#: Noise-free triangulation (see test_cli_geometry.py): float64 rounding, measured 4e-14 relative.
NOISE_FREE_REL_TOL = 1e-9
#: The 15-DoF projective alignment on the ~190 board points (16x16 SVD's conditioning, as in
#: metrics/test_metrics_dlt.py's DLT_TOL).
PROJECTIVE_TOL = 1e-7


@pytest.fixture(scope="session")
def scenes(tmp_path_factory):
    from scenegen.pipeline.run import render_spec

    root = tmp_path_factory.mktemp("geometry_scenes")
    render_spec(SCENES / "dlt_calibration_object.yaml", root / "dlt", progress=False)
    text = (SCENES / "triangulation_baselines.yaml").read_text()
    assert TRI_FULL in text
    (root / "tri.yaml").write_text(text.replace(TRI_FULL, TRI_SMALL))
    render_spec(root / "tri.yaml", root / "tri", spp=TRI_SPP, progress=False)
    return {"dlt": root / "dlt", "tri": root / "tri"}


@pytest.fixture(scope="session")
def runs(scenes, tmp_path_factory):
    from recon_eval.runners import run_method

    root = tmp_path_factory.mktemp("geometry_runs")
    run_method("dlt-linear", scenes["dlt"], root / "dlt")
    run_method("opencv-triangulate", scenes["tri"], root / "tri")
    return {k: (root / k, json.loads((root / k / "result.json").read_text())) for k in ("dlt", "tri")}


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


# --- DLT --------------------------------------------------------------------------------------
def test_dlt_runner_files_and_numbers(runs, scenes):
    from recon_eval.metrics.dlt import score_projection
    from recon_eval.readers.scenegen_dataset import read_dataset

    out, doc = runs["dlt"]
    ds = read_dataset(scenes["dlt"])
    assert len(ds.views) == 8
    for kind in ("targets", "points"):
        for v in ds.views:
            assert f"P/{kind}/{v}.txt" in doc["inputs"]["raw_files"]
            assert np.loadtxt(out / "P" / kind / f"{v}.txt").shape == (3, 4)
    m = doc["metrics"]
    assert m["targets.failure_ratio"] == 0.0 and m["points.failure_ratio"] == 0.0
    assert m["targets.median_fx_rel_err"] < DLT_TARGETS_FOCAL_REL
    assert m["targets.median_fy_rel_err"] < DLT_TARGETS_FOCAL_REL
    assert m["targets.median_rot_err_deg"] < DLT_TARGETS_ROT_DEG
    assert m["targets.median_center_err_m"] < DLT_TARGETS_CENTER_M
    assert m["targets.median_reproj_rms_px"] < DLT_TARGETS_REPROJ_PX
    assert m["points.median_fx_rel_err"] < DLT_POINTS_FOCAL_REL
    assert m["points.median_rot_err_deg"] < DLT_POINTS_ROT_DEG
    assert m["points.median_reproj_rms_px"] < DLT_POINTS_REPROJ_PX
    # every view saw all three boards
    assert all(len(c) == 3 and min(c.values()) >= 40 for c in doc["inputs"]["notes"]["detected_corners"].values())
    # the scores are those of the files: K and pose of one view recomputed from the file
    v = ds.views[0]
    cam, pose = ds.camera(v)
    s = score_projection(np.loadtxt(out / "P" / "targets" / f"{v}.txt"), cam.K, pose)
    assert s.fx_abs_err_px == doc["results"][f"targets.{v}"]["fx_abs_err_px"]


def test_detected_corners_match_the_per_view_corner_truth(scenes):
    from recon_eval.readers.scenegen_dataset import read_dataset
    from recon_eval.runners.detect import detect_board_points

    ds = read_dataset(scenes["dlt"])
    d = []
    for v in ds.views:
        truth = json.loads((scenes["dlt"] / "crossview" / "targets" / f"{v}.json").read_text())["boards"]
        for name, (geo, board) in ds.boards().items():
            x, X = detect_board_points(ds.image(v), geo, board)
            uv = {tuple(np.round(P, 9)): u for P, u in zip(truth[name]["points_world"], truth[name]["uv"])}
            d += [np.linalg.norm(xi - np.asarray(uv[tuple(np.round(Xi, 9))])) for xi, Xi in zip(x, X)]
    assert len(d) > 1000 and np.median(d) < DETECTION_MEDIAN_PX, np.median(d)


def test_rendered_marker_outlines_sit_on_the_corner_truth(scenes):
    from scipy.ndimage import map_coordinates

    from scenegen.dataset import codecs as sio

    root = scenes["dlt"]
    offsets = []
    for v in json.loads((root / "cameras.json").read_text())["view_order"]:
        lin = sio.read_exr(root / "images" / f"{v}_linear.exr")
        img = (lin["R"] + lin["G"] + lin["B"]) / 3.0
        for board in json.loads((root / "crossview" / "targets" / f"{v}.json").read_text())["boards"].values():
            uv = {pid: u for pid, u, st in zip(board["point_ids"], board["uv"], board["state"]) if st == 1}
            for marker in {pid // 4 for pid in uv}:  # aruco grid ids: marker_id * 4 + corner
                if not all(marker * 4 + k in uv for k in range(4)):
                    continue
                c = np.array([uv[marker * 4 + k] for k in range(4)], np.float64)
                for a, b in zip(c, np.roll(c, -1, axis=0)):
                    if np.linalg.norm(b - a) < OUTLINE_MIN_SIDE_PX:
                        continue
                    mid = (a + b) / 2
                    n = np.array([a[1] - b[1], b[0] - a[0]]) / np.linalg.norm(b - a)
                    n = n if n @ (mid - c.mean(axis=0)) > 0 else -n  # outward: black border -> white
                    s = np.linspace(-OUTLINE_PROFILE_PX, OUTLINE_PROFILE_PX, 601)
                    pts = mid + s[:, None] * n
                    prof = map_coordinates(img, [pts[:, 1], pts[:, 0]], order=1)
                    lo, hi = prof[s < -2.0].mean(), prof[s > 2.0].mean()
                    if hi - lo > 0.1:  # a lit edge with contrast
                        offsets.append(s[np.argmax(prof > (lo + hi) / 2)])
    assert len(offsets) > 500 and abs(np.median(offsets)) < OUTLINE_MEDIAN_PX, (len(offsets), np.median(offsets))


def test_dlt_cli_on_the_runner_output_and_projective_form(runs, scenes, tmp_path, capsys):
    from recon_eval.readers.scenegen_dataset import read_dataset

    out, doc = runs["dlt"]
    ds = read_dataset(scenes["dlt"])
    v = ds.views[2]
    code, _, err = run(["dlt", out / "P" / "targets" / f"{v}.txt", scenes["dlt"], "--view", v,
                        "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    cli = json.loads((tmp_path / "r.json").read_text())["results"]["dlt"]
    for f in ("fx_abs_err_px", "cy_abs_err_px", "rot_err_deg", "center_err_m"):  # same file, same K and pose
        assert cli[f] == pytest.approx(doc["results"][f"targets.{v}"][f], rel=1e-12)
    # projective frame: the truth camera and the boards' points under a random 3D homography
    cam, pose = ds.camera(v)
    rng = np.random.default_rng(5)
    H = np.eye(4) + 0.3 * rng.normal(size=(4, 4))  # truth_from_proj
    rows, X = [], []
    for name, (_, truth) in ds.boards().items():
        for pid, P in zip(truth["point_ids"], truth["points_world"]):
            rows.append((name, pid))
            X.append(P)
    Xh = np.hstack([np.asarray(X), np.ones((len(X), 1))]) @ np.linalg.inv(H).T
    lines = ["# BOARD ID X Y Z W"] + [f"{b} {i} " + " ".join(f"{c:.17g}" for c in x) for (b, i), x in zip(rows, Xh)]
    (tmp_path / "pts.txt").write_text("\n".join(lines) + "\n")
    np.savetxt(tmp_path / "P.txt", cam.K @ np.hstack([pose.R, pose.t[:, None]]) @ H, fmt="%.17g")
    code, _, err = run(["dlt", tmp_path / "P.txt", scenes["dlt"], "--view", v, "--projective-points",
                        tmp_path / "pts.txt", "--json", tmp_path / "p.json", "--quiet"], capsys)
    assert code == 0, err
    s = json.loads((tmp_path / "p.json").read_text())["results"]["dlt"]
    assert s["n_points"] == len(rows) > 150
    for f in ("fx_rel_err", "fy_rel_err", "cx_rel_err", "cy_rel_err", "rot_err_deg", "trans_rel_err", "reproj_rms_px"):
        assert s[f] < PROJECTIVE_TOL, (f, s[f])
    # ids that the board does not have, or a repeated one: file:line, exit 2
    (tmp_path / "bad.txt").write_text("\n".join(lines[:5] + ["floor_board 9999 1 2 3 1"]) + "\n")
    code, _, err = run(["dlt", tmp_path / "P.txt", scenes["dlt"], "--view", v, "--projective-points",
                        tmp_path / "bad.txt"], capsys)
    assert code == 2 and "bad.txt:6: board 'floor_board' has no point id 9999" in err
    (tmp_path / "dup.txt").write_text("\n".join(lines[:5] + [lines[2]]) + "\n")
    code, _, err = run(["dlt", tmp_path / "P.txt", scenes["dlt"], "--view", v, "--projective-points",
                        tmp_path / "dup.txt"], capsys)
    assert code == 2 and "dup.txt:6:" in err and "repeats line 3" in err


# --- triangulation ----------------------------------------------------------------------------
def test_triangulation_runner_files_and_numbers(runs):
    out, doc = runs["tri"]
    m = doc["metrics"]
    names = doc["inputs"]["notes"]["sigma1"]["pairs"]
    assert len(names) == 6
    for tag in ("sigma0", "sigma1"):
        for n in names:
            assert f"points_{tag}/{n}.txt" in doc["inputs"]["raw_files"]
            assert np.loadtxt(out / f"points_{tag}" / f"{n}.txt").shape == (2000, 3)
        assert (out / f"task_{tag}" / "task.json").is_file()
    assert m["sigma0.max_rel_err"] < NOISE_FREE_REL_TOL and m["sigma0.failure_ratio"] == 0.0
    # sigma 1 px: the median error per angle bin falls as the angle grows (bins with >= 100 points)
    bins = [b for b in doc["results"]["sigma1.all_pairs"]["bins"] if b["n"] >= 100]
    assert len(bins) >= 6
    med = [b["median_m"] for b in bins]
    assert all(b < a for a, b in itertools.pairwise(med)), med


def test_triangulation_cli_error_grows_as_angle_shrinks(scenes, tmp_path, capsys):
    code, _, err = run(["triangulation-task", scenes["tri"], "-o", tmp_path / "task", "--sigma", "1", "--count", "1000",
                        "--quiet"], capsys)
    assert code == 0, err
    code, _, err = run(["triangulation", tmp_path / "task", "--json", tmp_path / "r.json", "--html",
                        tmp_path / "r.html", "--quiet"], capsys)
    assert code == 0, err
    r = json.loads((tmp_path / "r.json").read_text())
    pairs = r["inputs"]["pairs"]  # ref against a01, a02, a05, a10, a20, a40
    assert [p.split("__")[1][:3] for p in pairs] == ["a01", "a02", "a05", "a10", "a20", "a40"]
    med = [r["results"][p]["median_m"] for p in pairs]
    assert all(b < a for a, b in itertools.pairwise(med)), med
    # first order: error ~ 1 / angle, so ~40x from 1 to 40 degrees
    assert med[0] / med[-1] > 15
    html = (tmp_path / "r.html").read_text()
    assert "Error vs triangulation angle" in html and "data:image/png;base64," in html


def test_not_applicable(scenes, tmp_path):
    from recon_eval.runners import NotApplicable, run_method

    with pytest.raises(NotApplicable, match="non-coplanar"):
        run_method("dlt-linear", scenes["tri"], tmp_path / "a", write=False)
    with pytest.raises(NotApplicable, match="cross-view pairs"):
        run_method("opencv-triangulate", scenes["dlt"], tmp_path / "b", write=False)


def test_geometry_gate_file_holds(runs, tmp_path):
    """gates/geometry.yaml (the project's gates for these methods) on the runs above."""
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[3]
    r = subprocess.run([sys.executable, "-m", "recon_eval", "gate", str(root / "gates" / "geometry.yaml"),
                        *(str(runs[k][0] / "result.json") for k in ("dlt", "tri"))], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "5 of 5 gates hold" in r.stdout


def test_zero_baseline_pairs_are_not_triangulated(tmp_path, capsys, zero_baseline_spec):
    """A roll about the optical axis keeps the camera centre: the pair is left out of a task built
    from the index (and listed), and naming it is an error; the runner notes it."""
    from recon_eval.runners import run_method
    from scenegen.pipeline.run import render_spec

    (tmp_path / "zb.yaml").write_text(zero_baseline_spec)
    render_spec(tmp_path / "zb.yaml", tmp_path / "ds", progress=False)
    code, _, err = run(["triangulation-task", tmp_path / "ds", "-o", tmp_path / "task", "--json",
                        tmp_path / "t.json", "--quiet"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "t.json").read_text())
    assert doc["inputs"]["skipped_zero_baseline_pairs"] == ["cam_0000:cam_0001"]
    assert list(doc["results"]["pairs"]) == ["cam_0000__cam_0002"]
    code, _, err = run(["triangulation-task", tmp_path / "ds", "-o", tmp_path / "t2", "--pairs",
                        "cam_0000:cam_0001"], capsys)
    assert code == 2 and "zero baseline" in err and "Traceback" not in err
    r = run_method("opencv-triangulate", tmp_path / "ds", tmp_path / "run")
    assert r["inputs"]["notes"]["skipped_zero_baseline_pairs"] == ["cam_0000:cam_0001"]
    assert r["metrics"]["sigma0.max_rel_err"] < NOISE_FREE_REL_TOL


@pytest.mark.render
def test_external_dlt_kind_equals_dlt_linear(runs, scenes, tmp_path):
    """The same DLT as a user's script on the {points} files: dlt-linear's numbers under its names."""
    from recon_eval.runners import run_method
    from recon_eval.runners.declared import external_method

    est = Path(__file__).resolve().parent / "estimators" / "linear_dlt.py"
    m = external_method("my-dlt", "dlt", f"{{python}} {est} {{points}} {{out}}")
    doc = run_method("my-dlt", scenes["dlt"], tmp_path / "mine", declared={"my-dlt": m})
    ref = runs["dlt"][1]
    assert doc["inputs"]["task"] == ref["inputs"]["task"] and doc["metrics"] == ref["metrics"]
