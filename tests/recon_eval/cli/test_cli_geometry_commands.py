"""``recon-eval dlt``, ``triangulation-task`` and ``triangulation`` end to end through files, on the
analytic plane dataset (tests/recon_eval/conftest.py: two pinhole views of a stereo rig
and a distorted OpenCV view) and on analytic cameras; bad input exits 2 with file:line messages.
The rendered scenes (calibration object, baseline series) are in runners/test_runners_geometry_scenes.py."""
from __future__ import annotations

import json

import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.metrics.dlt import project_with_P

#: Reprojection of the dataset's own truth points through the truth P: the truth points are
#: stored as float32 (~6e-8 relative, ~2e-7 m at 3 m), which at fx = 40 px and 3 m depth moves a
#: pixel by ~3e-6 px; measured max 1.1e-6 px (the distorted view's pixels undistorted through the
#: exact model included).
TRUTH_REPROJ_PX = 1e-5
#: RQ of an exactly built P: float64 rounding times the condition of K (see metrics/test_metrics_dlt.py).
EXACT_TOL = 1e-9
#: Noise-free triangulation through the task files: the files keep 17 significant digits, so the
#: only error is cv2.triangulatePoints' float64 DLT (~1e-14 relative measured); 1e-9 relative to
#: depth is the issue's "float precision" with margin.
NOISE_FREE_REL_TOL = 1e-9
#: Task observations against the dataset's correspondences. View 1: the pixel centre against the
#: projection of its float32-stored truth point (measured 6e-7 px at fx = 40 px). View 2 (distorted):
#: both project the same stored point, the correspondence through the distortion and back through
#: the exact inverse model (measured 1e-14 px). 1e-5 px: the float32 storage with a 10x margin.
UNDISTORT_AGREE_PX = 1e-5


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def result(path):
    return json.loads(path.read_text())


def write_P(path, P):
    np.savetxt(path, P, fmt="%.17g")
    return path


def truth_P(cams, view):
    cam, pose = cams[view]
    return cam.K @ np.hstack([pose.R, pose.t[:, None]])


# --- dlt: dataset truth -----------------------------------------------------------------------
@pytest.mark.parametrize("view", ["left_000", "free_000"])
def test_dlt_truth_P_scores_zero(plane_dataset, tmp_path, capsys, view):
    root, cams = plane_dataset
    P = write_P(tmp_path / "P.txt", -2.5 * truth_P(cams, view))  # any scale, either sign
    code, _, err = run(["dlt", P, root, "--view", view, "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    r = result(tmp_path / "r.json")
    s = r["results"]["dlt"]
    assert not s["failed"] and s["n_points"] == r["inputs"]["held_out_points"] > 500
    for f in ("fx_abs_err_px", "fy_abs_err_px", "cx_abs_err_px", "cy_abs_err_px", "skew_abs_err_px",
              "rot_err_deg", "trans_abs_err_m", "center_err_m"):
        assert s[f] < EXACT_TOL, (f, s[f])
    assert s["reproj_max_px"] < TRUTH_REPROJ_PX
    np.testing.assert_allclose(r["results"]["decomposition"]["K"], cams[view][0].K, rtol=EXACT_TOL, atol=EXACT_TOL)


def test_dlt_known_fx_error_reads_back_exactly(plane_dataset, tmp_path, capsys):
    root, cams = plane_dataset
    cam, pose = cams["free_000"]
    K = cam.K.copy()
    K[0, 0] += 2.0
    P = write_P(tmp_path / "P.txt", K @ np.hstack([pose.R, pose.t[:, None]]))
    code, _, err = run(["dlt", P, root, "--view", "free_000", "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    r = result(tmp_path / "r.json")
    s = r["results"]["dlt"]
    assert s["fx_abs_err_px"] == pytest.approx(2.0, abs=EXACT_TOL)
    assert s["fx_rel_err"] == pytest.approx(2.0 / cam.fx, abs=EXACT_TOL)
    for f in ("fy_abs_err_px", "cx_abs_err_px", "cy_abs_err_px", "rot_err_deg", "trans_abs_err_m"):
        assert s[f] < EXACT_TOL, (f, s[f])
    assert r["results"]["decomposition"]["K"][0][0] == pytest.approx(cam.fx + 2.0, abs=EXACT_TOL)
    # the held-out pixels see the 2 px focal error: |du| = 2 |x / z| over the image
    _, X = _held_out(root, "free_000")
    Xc = X @ pose.R.T + pose.t
    expect = 2.0 * np.abs(Xc[:, 0] / Xc[:, 2])
    assert s["reproj_max_px"] == pytest.approx(expect.max(), abs=1e-4)


def _held_out(root, view, n=5000):
    from recon_eval.readers.scenegen_dataset import read_dataset

    return read_dataset(root).points_at_pixels(view, max_points=n)


# --- dlt: K and pose files, projective frame --------------------------------------------------
@pytest.fixture
def synthetic(look_at_cam_from_world):
    """``synthetic(rng, n=60)``: (camera, R, t, points (n, 3), their pixels) of one pinhole view."""
    from scenegen.geometry.camera import Camera

    def make(rng, n=60):
        cam = Camera("pinhole", 640, 480, 610.0, 590.0, 321.5, 238.25, 1.5)
        R, t = look_at_cam_from_world([4.0, -3.0, 2.0], target=[0.1, 0.2, 0.0])
        X = rng.uniform(-1, 1, size=(n, 3))
        return cam, R, t, X, cam.project(X @ R.T + t)
    return make


def test_dlt_with_K_and_pose_files(tmp_path, capsys, synthetic):
    cam, R, t, X, px = synthetic(np.random.default_rng(1))
    np.savetxt(tmp_path / "K.txt", cam.K)
    (tmp_path / "pose.json").write_text(json.dumps({"R": R.tolist(), "t": t.tolist()}))
    np.save(tmp_path / "X.npy", X)
    np.save(tmp_path / "x.npy", px)
    R2 = np.array([[np.cos(0.01), -np.sin(0.01), 0], [np.sin(0.01), np.cos(0.01), 0], [0, 0, 1]]) @ R
    P = write_P(tmp_path / "P.txt", cam.K @ np.hstack([R2, t[:, None]]))
    code, _, err = run(["dlt", P, "--K", tmp_path / "K.txt", "--pose", tmp_path / "pose.json", "--points-world",
                        tmp_path / "X.npy", "--pixels", tmp_path / "x.npy", "--json", tmp_path / "r.json",
                        "--quiet"], capsys)
    assert code == 0, err
    s = result(tmp_path / "r.json")["results"]["dlt"]
    assert s["rot_err_deg"] == pytest.approx(np.degrees(0.01), abs=EXACT_TOL)
    assert s["fx_abs_err_px"] < EXACT_TOL and s["n_points"] == 60
    P_est = np.loadtxt(P)
    expect = np.sqrt(np.mean(np.sum((project_with_P(P_est, X) - px) ** 2, axis=1)))
    assert s["reproj_rms_px"] == pytest.approx(expect, rel=1e-12)


def test_dlt_projective_frame_without_dataset(tmp_path, capsys, synthetic):
    rng = np.random.default_rng(2)
    cam, R, t, X, px = synthetic(rng)
    H = np.eye(4) + 0.3 * rng.normal(size=(4, 4))  # truth_from_proj, a generic projective map
    Xh = np.hstack([X, np.ones((len(X), 1))]) @ np.linalg.inv(H).T
    Xh *= rng.uniform(0.5, 2.0, size=(len(X), 1))  # arbitrary homogeneous scale per point
    P_proj = cam.K @ np.hstack([R, t[:, None]]) @ H  # P_proj X_proj = P_true X_true
    np.savetxt(tmp_path / "pts.txt", Xh, fmt="%.17g", header="X Y Z W")
    np.savetxt(tmp_path / "truth.txt", X, fmt="%.17g")
    np.savetxt(tmp_path / "K.txt", cam.K)
    (tmp_path / "pose.json").write_text(json.dumps({"cam_from_world": {"R": R.tolist(), "t": t.tolist()}}))
    write_P(tmp_path / "P.txt", P_proj)
    argv = ["dlt", tmp_path / "P.txt", "--K", tmp_path / "K.txt", "--pose", tmp_path / "pose.json"]
    code, _, err = run(argv + ["--json", tmp_path / "raw.json", "--quiet"], capsys)
    assert code == 0, err
    raw = result(tmp_path / "raw.json")["results"]["dlt"]
    assert raw["failed"] or raw["rot_err_deg"] > 1.0 or raw["fx_rel_err"] > 0.1  # meaningless unaligned
    write_P(tmp_path / "nan.txt", np.full((3, 4), np.nan))  # a failed estimate: scored, not refused
    code, _, err = run(["dlt", tmp_path / "nan.txt", "--K", tmp_path / "K.txt", "--pose", tmp_path / "pose.json",
                        "--projective-points", tmp_path / "pts.txt", "--truth-points", tmp_path / "truth.txt",
                        "--json", tmp_path / "nan.json", "--quiet"], capsys)
    assert code == 0, err
    s = result(tmp_path / "nan.json")["results"]["dlt"]
    assert s["failed"] and s["rot_err_deg"] == "inf" and s["n_invalid"] == 60
    code, _, err = run(argv + ["--projective-points", tmp_path / "pts.txt", "--truth-points", tmp_path / "truth.txt",
                               "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    r = result(tmp_path / "r.json")
    assert r["inputs"]["alignment"] == "projective15"
    s = r["results"]["dlt"]
    for f in ("fx_rel_err", "fy_rel_err", "cx_rel_err", "cy_rel_err", "skew_abs_err_px", "rot_err_deg",
              "trans_abs_err_m", "reproj_rms_px"):
        assert s[f] < 1e-7, (f, s[f])  # metrics/test_metrics_dlt.py's DLT_TOL: the 16x16 SVD's conditioning


def test_dlt_bad_input_exit_2(plane_dataset, tmp_path, capsys):
    root, cams = plane_dataset
    good = write_P(tmp_path / "P.txt", truth_P(cams, "left_000"))
    (tmp_path / "bad.txt").write_text("# P\n1 2 3 4\n5 6 seven 8\n9 10 11 12\n")
    (tmp_path / "short.txt").write_text("1 2 3 4\n5 6 7 8\n")
    (tmp_path / "wide.txt").write_text("1 2 3 4\n5 6 7 8 9\n1 1 1 1\n")
    cases = [
        (["dlt", tmp_path / "bad.txt", root, "--view", "left_000"], "bad.txt:3: 'seven' is not a number"),
        (["dlt", tmp_path / "short.txt", root, "--view", "left_000"], "3x4 camera matrix"),
        (["dlt", tmp_path / "wide.txt", root, "--view", "left_000"], "wide.txt:2: expected 4 fields"),
        (["dlt", good, root], "--view"),
        (["dlt", good, root, "--view", "nope"], "view 'nope'"),
        (["dlt", good], "--K K.txt and --pose"),
        (["dlt", good, "--K", tmp_path / "P.txt"], "--K K.txt and --pose"),
        (["dlt", good, tmp_path], "not a scenegen dataset"),
    ]
    (tmp_path / "pts.txt").write_text("board 0 1 2 3\n")
    cases.append((["dlt", good, root, "--view", "left_000", "--projective-points", tmp_path / "pts.txt"],
                  "pts.txt:1: no board 'board'"))
    np.savetxt(tmp_path / "K.txt", cams["left_000"][0].K)
    np.savetxt(tmp_path / "pose.txt", np.hstack([cams["left_000"][1].R, cams["left_000"][1].t[:, None]]))
    plane = np.random.default_rng(0).uniform(-1, 1, size=(10, 3)) * [1, 1, 0]  # coplanar: no 15-DoF alignment
    np.savetxt(tmp_path / "flat.txt", plane)
    cases.append((["dlt", good, "--K", tmp_path / "K.txt", "--pose", tmp_path / "pose.txt", "--projective-points",
                   tmp_path / "flat.txt", "--truth-points", tmp_path / "flat.txt"], "coplanar"))
    (tmp_path / "w0.txt").write_text("".join(f"{x} {y} {z} 1\n" for x, y, z in plane[:9]) + "1 2 3 0\n")
    cases.append((["dlt", good, "--K", tmp_path / "K.txt", "--pose", tmp_path / "pose.txt", "--projective-points",
                   tmp_path / "w0.txt", "--truth-points", tmp_path / "flat.txt"], "w0.txt:10: a projective point"))
    for argv, msg in cases:
        code, _, err = run(argv, capsys)
        assert code == 2, (argv, err)
        assert msg in err and "Traceback" not in err, (msg, err)


# --- triangulation ----------------------------------------------------------------------------
def _task(root, out, capsys, *extra):
    code, _, err = run(["triangulation-task", root, "-o", out, "--pairs", "left_000:right_000", "left_000:free_000",
                        "--quiet", *extra], capsys)
    assert code == 0, err
    return json.loads((out / "task.json").read_text())


def _linear_triangulation(P1, P2, x1, x2):
    """Textbook homogeneous DLT triangulation (H&Z sec. 12.2), an implementation independent of
    OpenCV's, with each row pair normalised."""
    X = []
    for a, b in zip(x1, x2):
        A = np.stack([a[0] * P1[2] - P1[0], a[1] * P1[2] - P1[1], b[0] * P2[2] - P2[0], b[1] * P2[2] - P2[1]])
        A /= np.linalg.norm(A, axis=1, keepdims=True)
        v = np.linalg.svd(A)[2][-1]
        X.append(v[:3] / v[3])
    return np.asarray(X)


def test_noise_free_task_recovers_truth_through_files(plane_dataset, tmp_path, capsys):
    root, cams = plane_dataset
    doc = _task(root, tmp_path / "task", capsys, "--sigma", "0")
    assert [p["name"] for p in doc["pairs"]] == ["left_000__right_000", "left_000__free_000"]
    # the reference method (OpenCV) through the files
    code, _, err = run(["triangulation", tmp_path / "task", "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    r = result(tmp_path / "r.json")["results"]
    assert r["all_pairs"]["n_points"] == sum(p["n_points"] for p in doc["pairs"]) > 1000
    assert max(r["all_pairs"]["rel_err"]) < NOISE_FREE_REL_TOL
    # a user's answer: an independent triangulator run on the task files alone
    est = tmp_path / "est"
    est.mkdir()
    for p in doc["pairs"]:
        P1, P2 = (np.loadtxt(tmp_path / "task" / p["files"][k]) for k in ("P1", "P2"))
        obs = np.loadtxt(tmp_path / "task" / p["files"]["observations"])
        np.savetxt(est / f"{p['name']}.txt", _linear_triangulation(P1, P2, obs[:, :2], obs[:, 2:]), fmt="%.17g")
    code, _, err = run(["triangulation", tmp_path / "task", est, "--json", tmp_path / "u.json", "--quiet"], capsys)
    assert code == 0, err
    u = result(tmp_path / "u.json")
    assert u["inputs"]["method"] == "user" and u["results"]["all_pairs"]["n_failed"] == 0
    assert max(u["results"]["all_pairs"]["rel_err"]) < NOISE_FREE_REL_TOL


def test_task_observations_are_undistorted_truth_correspondences(plane_dataset, tmp_path):
    from recon_eval.readers.scenegen_dataset import read_dataset
    from scenegen.geometry.twoview import undistorted_pixels
    from recon_eval.tasks.triangulation_task import build_pair

    root, cams = plane_dataset
    ds = read_dataset(root)
    tp = build_pair(ds, "left_000", "free_000", 0.0, count=100_000)
    x1, x2 = ds.correspondences("left_000", "free_000", max_points=100_000)
    assert len(tp.points_true) == len(x1) > 500  # every visible correspondence, same order
    np.testing.assert_allclose(tp.observations[:, :2], x1, atol=UNDISTORT_AGREE_PX)  # pinhole view 1
    np.testing.assert_allclose(tp.observations[:, 2:], undistorted_pixels(cams["free_000"][0], x2), atol=UNDISTORT_AGREE_PX)


def test_task_is_deterministic_and_noise_is_sigma(plane_dataset, tmp_path, capsys):
    root, _ = plane_dataset
    a = _task(root, tmp_path / "a", capsys, "--sigma", "1.5", "--seed", "4")
    _task(root, tmp_path / "b", capsys, "--sigma", "1.5", "--seed", "4")
    _task(root, tmp_path / "z", capsys, "--sigma", "0", "--seed", "4")
    for p in a["pairs"]:
        for f in p["files"].values():
            assert (tmp_path / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes()
        # the same truth points at any sigma; the noise is N(0, sigma^2) per coordinate
        f = p["files"]["truth"]
        assert (tmp_path / "a" / f).read_bytes() == (tmp_path / "z" / f).read_bytes()
    d = np.concatenate([np.loadtxt(tmp_path / "a" / p["files"]["observations"])
                        - np.loadtxt(tmp_path / "z" / p["files"]["observations"]) for p in a["pairs"]]).ravel()
    # sample std of ~5000 normal draws: 1.5 +- 3 standard errors (1.5 / sqrt(2 n))
    assert abs(d.std() - 1.5) < 3 * 1.5 / np.sqrt(2 * len(d)) and abs(d.mean()) < 3 * 1.5 / np.sqrt(len(d))


def test_answer_failures_and_bad_answers(plane_dataset, tmp_path, capsys):
    root, _ = plane_dataset
    doc = _task(root, tmp_path / "task", capsys, "--sigma", "0", "--count", "50")
    est = tmp_path / "est"
    est.mkdir()
    p0, p1 = doc["pairs"]
    X0 = np.loadtxt(tmp_path / "task" / p0["files"]["truth"])
    X0[7] = np.nan  # a point not triangulated
    np.savetxt(est / f"{p0['name']}.txt", X0[:45], fmt="%.17g")  # and 5 rows missing at the end
    # pair 1: no answer file at all -> all its points fail
    code, _, err = run(["triangulation", tmp_path / "task", est, "--json", tmp_path / "r.json", "--quiet"], capsys)
    assert code == 0, err
    r = result(tmp_path / "r.json")
    s0 = r["results"][p0["name"]]
    assert s0["n_points"] == 50 and s0["n_failed"] == 6 and s0["mean_m"] == "inf" and s0["median_m"] == 0.0
    assert r["results"][p1["name"]]["n_failed"] == p1["n_points"]
    assert r["inputs"]["missing_files"] == [f"{p1['name']}.txt"]
    assert r["inputs"]["short_files"][f"{p0['name']}.txt"] == {"rows": 45, "observations": 50}
    # malformed answers: file:line, exit 2
    (est / f"{p0['name']}.txt").write_text("1 2 3\n1 2\n")
    code, _, err = run(["triangulation", tmp_path / "task", est], capsys)
    assert code == 2 and f"{p0['name']}.txt:2: expected 3 fields" in err
    np.savetxt(est / f"{p0['name']}.txt", np.zeros((51, 3)))
    code, _, err = run(["triangulation", tmp_path / "task", est], capsys)
    assert code == 2 and f"{p0['name']}.txt:51: more rows than observations" in err
    code, _, err = run(["triangulation", tmp_path / "task", tmp_path / "empty_missing"], capsys)
    assert code == 2 and "no such folder" in err
    (tmp_path / "none").mkdir()
    code, _, err = run(["triangulation", tmp_path / "task", tmp_path / "none"], capsys)
    assert code == 2 and "no answer file for any pair" in err


def test_task_bad_input_exit_2(plane_dataset, tmp_path, capsys):
    root, _ = plane_dataset
    cases = [
        (["triangulation-task", root, "-o", tmp_path / "t"], "no view pairs given"),  # no crossview index
        (["triangulation-task", root, "-o", tmp_path / "t", "--pairs", "left_000"], "expected VIEW1:VIEW2"),
        (["triangulation-task", root, "-o", tmp_path / "t", "--pairs", "left_000:nope"], "view 'nope'"),
        (["triangulation-task", root, "-o", tmp_path / "t", "--pairs", "left_000:left_000"], "must differ"),
        (["triangulation-task", root, "-o", tmp_path / "t", "--pairs", "left_000:right_000", "--sigma", "-1"],
         "--sigma"),
        (["triangulation", tmp_path], "not a triangulation task"),
    ]
    for argv, msg in cases:
        code, _, err = run(argv, capsys)
        assert code == 2 and msg in err and "Traceback" not in err, (argv, err)
    doc = _task(root, tmp_path / "task", capsys, "--count", "20")
    obs = tmp_path / "task" / doc["pairs"][0]["files"]["observations"]
    obs.write_text(obs.read_text() + "1 2 3 4\n")
    code, _, err = run(["triangulation", tmp_path / "task"], capsys)
    assert code == 2 and "21 rows, task.json says n_points = 20" in err
