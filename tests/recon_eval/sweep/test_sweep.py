"""recon-eval sweep (issue 34): seeded trials, the survey's measure per cell, breakdown points,
the lecture's conclusions measured on exact truth, bitwise reproducibility, a user's command."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.epipolar import epipolar_line_distances_px
from recon_eval.runners.common import RunOutput
from recon_eval.runners.declared import external_method
from recon_eval.sweep.draw import draw_trial
from recon_eval.sweep.methods import resolve
from recon_eval.sweep.run import SweepConfig, run_sweep
from recon_eval.sweep.summary import breakdown_points, score_trial, summarise_cell
from recon_eval.tasks.fmatrix_pair import PairTruth

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def truth(two_view_points):
    """A PairTruth of 2000 exact correspondences (closed form: wide_baseline's cameras)."""
    x1, x2, F, K, rel = two_view_points(2000, 11)
    return PairTruth(x1, x2, F, K, K, rel.R, rel.t, (480, 360), (480, 360), "undistorted", {})


def test_trial_draws_are_seeded_per_cell_and_have_the_stated_noise(truth):
    a = draw_trial(truth.x1, truth.x2, (480, 360), 1500, 2.0, 0.2, 7, (1, 2), 3)
    b = draw_trial(truth.x1, truth.x2, (480, 360), 1500, 2.0, 0.2, 7, (1, 2), 3)
    assert all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("x1", "x2", "t1", "t2", "inliers"))
    c = draw_trial(truth.x1, truth.x2, (480, 360), 1500, 2.0, 0.2, 7, (1, 2), 4)
    assert not np.array_equal(a.x1, c.x1)
    assert (~a.inliers).sum() == 300
    e = np.r_[(a.x1 - a.t1).ravel(), (a.x2 - a.t2)[a.inliers].ravel()]
    # 5400 N(0, 4) draws: the sample std within 5 standard errors (sigma / sqrt(2 n) ~ 0.019 px)
    assert abs(np.std(e) - 2.0) < 5 * 2.0 / np.sqrt(2 * len(e)) and abs(np.mean(e)) < 5 * 2.0 / np.sqrt(len(e))
    out = a.x2[~a.inliers]
    assert np.all((out >= -0.5) & (out <= [479.5, 359.5]))
    with pytest.raises(InputError, match="fewer than --points"):
        draw_trial(truth.x1[:10], truth.x2[:10], (480, 360), 20, 0.0, 0.0, 0, (0, 0), 0)


def test_cell_statistics_pool_the_trials(truth):
    """Pooled mean and std from per-trial (mean, std) equal those of the concatenated distances."""
    trials, dists = [], []
    for k in range(4):
        t = draw_trial(truth.x1, truth.x2, (480, 360), 100, 1.0, 0.1, 0, (0, 0), k)
        F = truth.F_gt + 1e-7 * np.random.default_rng(k).normal(size=(3, 3))
        U, s, Vt = np.linalg.svd(F)
        F = U @ np.diag([s[0], s[1], 0]) @ Vt
        trials.append(score_trial(F, t, truth))
        dists.append(np.concatenate(epipolar_line_distances_px(F, t.t1[t.inliers], t.t2[t.inliers])))
    trials.append(score_trial(None, t, truth))  # a failure
    c = summarise_cell(trials, 1.0)
    d = np.concatenate(dists)
    assert abs(c["epi_mean_px"] - d.mean()) <= 1e-12 * d.mean() and abs(c["epi_std_px"] - d.std()) <= 1e-9 * d.std()
    assert c["n_failed"] == 1 and c["success_rate"] == 4 / 5
    assert c["median_trial_epi_px"] == np.median([t["epi_mean_px"] for t in trials])


def test_breakdown_is_the_first_fraction_above_the_threshold():
    def cell(m, f, e):
        return {"method": m, "family": "x", "sigma_px": 1.0, "outlier_fraction": f, "median_trial_epi_px": e}

    cells = [cell("a", 0.0, 0.2), cell("a", 0.2, 3.0), cell("a", 0.1, 0.5), cell("a", 0.3, 0.1),
             cell("b", 0.0, 0.2), cell("b", 0.1, 0.9), cell("b", 0.2, float("inf"))]
    rows = {r["method"]: r for r in breakdown_points(cells, 1.0)}
    assert rows["a"]["breakdown_fraction"] == 0.2 and rows["b"]["breakdown_fraction"] == 0.2
    rows = {r["method"]: r for r in breakdown_points(cells[:3], 5.0)}
    assert rows["a"]["breakdown_fraction"] is None and rows["a"]["max_fraction_swept"] == 0.2


#: The lecture's conclusions, on exact truth (docs/fmatrix_survey.md has the full sweep).
CONCLUSIONS = SweepConfig((0.0, 0.5, 2.0), (0.0, 0.3), 3, 200, 5, 1.0)


@pytest.fixture(scope="module")
def conclusions(truth, tmp_path_factory):
    methods = resolve(["survey-f-eight-point-eigen", "survey-f-fns", "survey-f-cfns", "survey-f-ransac",
                       "survey-f-lmeds-eigen", "survey-f-mapsac"], {}, RunOutput())
    res = run_sweep(truth, methods, CONCLUSIONS, tmp_path_factory.mktemp("work"))
    return {(c["method"].removeprefix("survey-f-"), c["sigma_px"], c["outlier_fraction"]): c for c in res["cells"]}


def test_every_method_is_exact_without_noise_or_outliers(conclusions):
    for m in ("eight-point-eigen", "fns", "cfns", "ransac", "lmeds-eigen", "mapsac"):
        assert conclusions[(m, 0.0, 0.0)]["epi_mean_px"] < 1e-9


def test_linear_and_iterative_cope_with_noise_not_outliers(conclusions):
    for m in ("eight-point-eigen", "fns", "cfns"):
        lo, hi = conclusions[(m, 0.5, 0.0)]["epi_mean_px"], conclusions[(m, 2.0, 0.0)]["epi_mean_px"]
        assert 0 < lo < hi < CONCLUSIONS.breakdown  # noise-sensitive, and below 1 px at 2 px noise
        assert 2.5 < hi / lo < 6  # about linear in sigma (x4)
        assert conclusions[(m, 0.5, 0.3)]["median_trial_epi_px"] > 10 * CONCLUSIONS.breakdown  # 30 % outliers
    # FNS/CFNS minimise the Sampson cost: at 2 px their Sampson RMS on the truth is no worse than 8-point's
    eight = conclusions[("eight-point-eigen", 2.0, 0.0)]["sampson_rms_px"]
    assert conclusions[("cfns", 2.0, 0.0)]["sampson_rms_px"] <= 1.05 * eight


def test_robust_methods_cope_with_both(conclusions):
    for m in ("ransac", "lmeds-eigen", "mapsac"):
        c = conclusions[(m, 0.5, 0.3)]
        assert c["median_trial_epi_px"] < CONCLUSIONS.breakdown and c["success_rate"] == 1.0


def test_sweep_is_bitwise_reproducible(truth, tmp_path):
    cfg = SweepConfig((1.0,), (0.0, 0.4), 2, 60, 3, 1.0)
    docs = []
    for k in range(2):
        methods = resolve(["survey-f-mlesac", "survey-f-lmeds-ls", "survey-f-parameter-space", "opencv-f-lmeds"], {},
                          RunOutput())
        docs.append(json.dumps(run_sweep(truth, methods, cfg, tmp_path / str(k)), allow_nan=True).encode())
    assert docs[0] == docs[1]
    cfg2 = SweepConfig((1.0,), (0.0, 0.4), 2, 60, 4, 1.0)
    methods = resolve(["survey-f-mlesac"], {}, RunOutput())
    assert json.dumps(run_sweep(truth, methods, cfg2, tmp_path / "2"), allow_nan=True).encode() != docs[0]


@pytest.mark.parametrize("cfg,msg", [((( -1.0,), (0.0,), 1, 50, 0, 1.0), "--sigmas"),
                                     (((0.0,), (1.0,), 1, 50, 0, 1.0), "--outliers"),
                                     (((0.0,), (0.9,), 1, 50, 0, 1.0), "fewer than 8 inliers"),
                                     (((0.0,), (0.0,), 0, 50, 0, 1.0), "--trials")])
def test_bad_configuration_is_refused(cfg, msg):
    with pytest.raises(InputError, match=msg):
        SweepConfig(*cfg).check()


#: A user's F method on the command line: OpenCV's 8-point on the trial's matches.
EIGHT_POINT_CMD = ('{python} -c "import sys, numpy as np, cv2; m = np.load(sys.argv[1]); '
                   'F, _ = cv2.findFundamentalMat(m[:, :2], m[:, 2:], cv2.FM_8POINT); np.savetxt(sys.argv[2], F)" '
                   '{matches} {out}')


def _sweep_cli(dataset, out, *extra):
    return subprocess.run([sys.executable, "-m", "recon_eval", "sweep", str(dataset), "-o", str(out), "--views",
                           "left_000", "right_000", "--sigmas", "0.5", "--outliers", "0", "0.2", "--trials", "2",
                           "--points", "40", "--quiet", *extra], capture_output=True, text=True, cwd=ROOT)


def test_cli_sweep_with_a_users_command_is_reproducible(plane_dataset, tmp_path):
    """On the analytic plane dataset's stereo pair (its truth correspondences); the user's command
    (OpenCV's 8-point through {matches}) scores exactly as the built-in opencv-f-8point."""
    root, _ = plane_dataset
    extra = ["--methods", "opencv-f-8point", "survey-f-ransac", "--command", EIGHT_POINT_CMD, "--name", "mine",
             "--markdown", str(tmp_path / "t.md")]
    r1 = _sweep_cli(root, tmp_path / "a", *extra)
    assert r1.returncode == 0, r1.stderr
    r2 = _sweep_cli(root, tmp_path / "b", *extra)
    assert r2.returncode == 0, r2.stderr
    a, b = (tmp_path / "a" / "sweep.json").read_bytes(), (tmp_path / "b" / "sweep.json").read_bytes()
    ja, jb = json.loads(a), json.loads(b)
    assert ja["results"]["cells"] == jb["results"]["cells"] and ja["results"]["breakdown"] == jb["results"]["breakdown"]
    cells = {(c["method"], c["outlier_fraction"]): c for c in ja["results"]["cells"]}
    for f in (0.0, 0.2):
        mine, builtin = dict(cells[("mine", f)]), dict(cells[("opencv-f-8point", f)])
        assert mine.pop("method") == "mine" and mine.pop("family") == "yours"
        builtin.pop("method"), builtin.pop("family")
        assert mine == builtin
    assert ja["inputs"]["methods"]["mine"]["params"]["command"] == EIGHT_POINT_CMD
    page = (tmp_path / "a" / "report.html").read_text()
    assert page.count("data:image/png;base64,") == 2 and "Error against noise" in page  # noise; outliers at 0.5 px
    assert "| `mine` | yours |" in (tmp_path / "t.md").read_text()


def test_cli_sweep_bad_input_exits_2(plane_dataset, tmp_path):
    root, _ = plane_dataset
    r = _sweep_cli(root, tmp_path / "o", "--methods", "survey-f-nine-point")
    assert r.returncode == 2 and "unknown method 'survey-f-nine-point'" in r.stderr and "Traceback" not in r.stderr
    r = _sweep_cli(root, tmp_path / "o", "--command", "{python} x.py {images} {out}")
    assert r.returncode == 2 and "{matches}" in r.stderr and "Traceback" not in r.stderr
    r = _sweep_cli(root, tmp_path / "o", "--methods", "opencv-f-7point")
    assert r.returncode == 2 and "exactly seven points" in r.stderr


def test_a_failing_command_is_a_failed_trial_never_dropped(truth, tmp_path):
    m = external_method("crashes", "fmatrix", '{python} -c "import sys; sys.exit(3)" {matches} {out}')
    notes = RunOutput()
    res = run_sweep(truth, resolve(["crashes"], {"crashes": m}, notes), SweepConfig((0.5,), (0.0,), 2, 30, 0, 1.0),
                    tmp_path)
    (cell,) = res["cells"]
    assert cell["n_failed"] == 2 and cell["success_rate"] == 0 and cell["median_trial_epi_px"] == float("inf")
    assert len(cell["trials"]) == 2 and all(n["failed"] == "exit status 3" for n in notes.notes.values())
