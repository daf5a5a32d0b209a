"""``run --command`` for the kinds of recon_eval.runners.external_more (flow, depth, essential), each
with a tiny estimator script of tests/recon_eval/runners/estimators/; one name per number between
a run and the same estimate scored by hand (README's gate line run as written); the warnings on
silent bad output (a NaN F or E, a disparity of the wrong sign). No Mitsuba: the analytic
two-frame flow dataset of tests/recon_eval/conftest.py."""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.runners import run_method
from recon_eval.runners.declared import external_method
from recon_eval.tasks.disparity_sign import reversed_sign_hint
from scenegen.dataset import Dataset

EST = Path(__file__).resolve().parent / "estimators"


def _run(ds, kind, command, tmp_path, name="mine"):
    m = external_method(name, kind, command)
    return run_method(name, ds, tmp_path / name, declared={name: m})


def test_flow_kind_equals_the_builtin_dis(flow_dataset, tmp_path):
    """A user's DIS script and opencv-flow-dis give the same numbers under the same names."""
    root, _ = flow_dataset
    mine = _run(root, "flow", f"{{python}} {EST / 'dis_flow.py'} {{image1}} {{image2}} {{out}}", tmp_path)
    ref = run_method("opencv-flow-dis", root, tmp_path / "ref")
    assert mine["metrics"] == ref["metrics"] and set(mine["metrics"]) >= {"epe_all_px", "fl_all_all_pct"}
    assert mine["inputs"]["task"] == ref["inputs"]["task"] == "optical flow"
    assert np.isfinite(mine["metrics"]["epe_all_px"]) and mine["metrics"]["epe_all_px"] < 1.0


def test_depth_kind_scores_a_known_scale_error(flow_dataset, tmp_path, capsys):
    """Truth x 1.1: abs_rel 0.1 and a1 1 without alignment, 0 after median scaling; the same names
    as ``recon-eval depth --json`` on the same file."""
    root, _ = flow_dataset
    doc = _run(root, "depth", f"{{python}} {EST / 'scaled_depth.py'} {{dataset}} {{view}} {{out}} 1.1", tmp_path)
    m = doc["metrics"]
    assert m["abs_rel"] == pytest.approx(0.1, abs=1e-6) and m["a1"] == 1.0
    assert m["median.abs_rel"] == pytest.approx(0.0, abs=1e-6) and m["coverage"] == 1.0
    view = Dataset(root).views[0]
    est = tmp_path / "mine" / "depth" / f"{view}.npy"
    assert main(["depth", str(est), str(root), "--view", view, "--json", str(tmp_path / "d.json"), "--quiet"]) == 0
    by_hand = json.loads((tmp_path / "d.json").read_text())["metrics"]
    assert by_hand["abs_rel"] == pytest.approx(0.1, abs=1e-6) and set(by_hand) == {k for k in m if "." not in k}


def test_essential_kind_true_E_and_a_nan_E(flow_dataset, tmp_path, capsys):
    root, _ = flow_dataset
    cmd = f"{{python}} {EST / 'true_two_view.py'} E {{dataset}} {{view1}} {{view2}} {{out}}"
    doc = _run(root, "essential", cmd, tmp_path)
    assert doc["metrics"]["pose_err_deg"] < 1e-4 and doc["inputs"]["task"] == "essential matrix"
    capsys.readouterr()
    doc = _run(root, "essential", cmd + " --nan", tmp_path, name="nan-e")
    err = capsys.readouterr().err
    assert doc["metrics"]["pose_err_deg"] == "inf"
    assert "recon-eval: warning: nan-e: cam_000__cam_001: the estimated E is non-finite" in err


def test_nan_f_is_scored_inf_with_a_warning_naming_pair_and_method(flow_dataset, tmp_path, capsys):
    root, _ = flow_dataset
    cmd = f"{{python}} {EST / 'true_two_view.py'} F {{dataset}} {{view1}} {{view2}} {{out}} --nan"
    doc = _run(root, "fmatrix", cmd, tmp_path, name="nan-f")
    err = capsys.readouterr().err
    assert doc["metrics"]["sampson_rms_px"] == "inf"
    assert "recon-eval: warning: nan-f: cam_000__cam_001: the estimated F is non-finite" in err
    assert doc["inputs"]["warnings"] == [err.strip().split("warning: nan-f: ")[1]]
    f = tmp_path / "nan-f" / "cam_000__cam_001" / "F.txt"
    assert main(["fmatrix", str(f), "--dataset", str(root), "--views", "cam_000", "cam_001", "--method", "by-hand",
                 "--quiet"]) == 0
    assert "recon-eval: warning: by-hand: cam_000__cam_001: the estimated F is non-finite" in capsys.readouterr().err


def test_readme_gate_line_gates_a_run_and_the_same_f_by_hand(flow_dataset, tmp_path, monkeypatch, capsys):
    """README: ``recon-eval gate my_gates.yaml f.json runs/*/result.json``, as written, on a run of
    a user's F and the same F scored by hand: one metric name, one number."""
    root, _ = flow_dataset
    monkeypatch.chdir(tmp_path)
    cmd = f"{{python}} {EST / 'true_two_view.py'} F {{dataset}} {{view1}} {{view2}} {{out}}"
    assert main(["run", "--command", cmd, "--kind", "fmatrix", "--name", "my-fmatrix", str(root), "-o",
                 "runs/my-f"]) == 0
    assert main(["fmatrix", "runs/my-f/cam_000__cam_001/F.txt", "--dataset", str(root), "--views", "cam_000",
                 "cam_001", "--method", "mine", "--json", "f.json", "--quiet"]) == 0
    Path("my_gates.yaml").write_text(
        "version: 1\ngates:\n"
        "  - {method: '*', metric: sampson_rms_px, op: '<=', threshold: 0.01}\n"
        "  - {method: '*', metric: pose_err_deg, op: '<=', threshold: 0.01}\n"
        "  - {method: '*', metric: f_distance_px, op: '<=', threshold: 0.01}\n")
    capsys.readouterr()
    argv = "gate my_gates.yaml f.json runs/*/result.json".split()
    import glob
    expanded = [p for a in argv for p in (sorted(glob.glob(a)) if "*" in a else [a])]  # as the shell does
    assert main(expanded) == 0, capsys.readouterr()
    run_doc, hand = (json.loads(Path(p).read_text()) for p in ("runs/my-f/result.json", "f.json"))
    assert set(hand["metrics"]) == set(run_doc["metrics"]) == {"sampson_rms_px", "pose_err_deg", "f_distance_px"}
    assert hand["metrics"] == run_doc["metrics"]
    # a gate that fails the run fails the by-hand score the same way
    Path("strict.yaml").write_text("version: 1\ngates:\n  - {method: '*', metric: sampson_rms_px, op: '<', "
                                   "threshold: 0.0}\n")
    assert main(["gate", "strict.yaml", "f.json"]) == 1 and main(["gate", "strict.yaml", "runs/my-f/result.json"]) == 1
    assert os.path.isfile("runs/my-f/result.json")


def test_reversed_disparity_hint(tmp_path, capsys):
    rng = np.random.default_rng(0)
    gt = rng.uniform(5.0, 30.0, (24, 32))
    assert reversed_sign_hint(gt + rng.normal(0, 0.3, gt.shape), gt) is None
    assert reversed_sign_hint(np.full_like(gt, np.nan), gt) is None  # missing everywhere: not a sign error
    hint = reversed_sign_hint(-gt, gt)
    assert hint.startswith("100.0 % of the pixels are bad at 2 px, 0.0 % with the disparity negated")
    np.save(tmp_path / "est.npy", -gt)
    np.save(tmp_path / "gt.npy", gt)
    assert main(["disparity", str(tmp_path / "est.npy"), str(tmp_path / "gt.npy"), "--quiet"]) == 0
    assert "is its sign reversed?" in capsys.readouterr().err


def test_features_kind_equals_the_builtin_sift(flow_dataset, tmp_path):
    root, _ = flow_dataset
    mine = _run(root, "features", f"{{python}} {EST / 'sift_features.py'} {{images}} {{pairs}} {{out}}", tmp_path)
    ref = run_method("opencv-features-sift", root, tmp_path / "ref")
    assert mine["metrics"] == ref["metrics"] and mine["inputs"]["task"] == ref["inputs"]["task"]
    assert mine["metrics"]["mma_3"] > 0.5


def test_pnp_kind_equals_the_builtin_sqpnp_on_the_points_input(flow_dataset, tmp_path):
    root, _ = flow_dataset
    mine = _run(root, "pnp", f"{{python}} {EST / 'sqpnp.py'} {{points}} {{k}} {{dist}} {{out}}", tmp_path)
    ref = run_method("opencv-pnp-sqpnp", root, tmp_path / "ref")
    points = {k: v for k, v in ref["metrics"].items() if k.startswith("points.")}
    assert mine["metrics"] == points and mine["inputs"]["task"] == ref["inputs"]["task"]
    assert mine["metrics"]["points.failure_ratio"] == 0.0


def test_cloud_kind_and_recon_eval_cloud_agree(plane_dataset, tmp_path):
    """1681 points on the plane and one 0.5 m above it: precision 1681/1682 before downsampling (the
    voxels keep each point apart at 5 mm), the same headline as ``recon-eval cloud --json``."""
    root, _ = plane_dataset
    doc = _run(root, "cloud", f"{{python}} {EST / 'plane_cloud.py'} {{out}}", tmp_path)
    m = doc["metrics"]
    assert m["tnt_precision_at_1cm"] == pytest.approx(1681 / 1682, abs=1e-12) and 0 < m["tnt_recall_at_1cm"] < 0.2
    assert doc["inputs"]["task"] == "point clouds and meshes"
    out = tmp_path / "c.json"
    assert main(["cloud", str(tmp_path / "mine" / "cloud.ply"), str(root), "--json", str(out), "-q"]) == 0
    assert json.loads(out.read_text())["metrics"] == m


def test_triangulation_kind_equals_the_builtin(flow_dataset, tmp_path):
    """A user's cv2.triangulatePoints script on the task folders: opencv-triangulate's numbers and names."""
    root, _ = flow_dataset
    mine = _run(root, "triangulation", f"{{python}} {EST / 'dlt_triangulate.py'} {{task}} {{out}}", tmp_path)
    ref = run_method("opencv-triangulate", root, tmp_path / "ref")
    assert mine["inputs"]["task"] == ref["inputs"]["task"] and set(mine["metrics"]) == set(ref["metrics"])
    assert mine["metrics"] == pytest.approx(ref["metrics"], rel=1e-9, abs=1e-15)
    assert mine["metrics"]["sigma0.median_err_m"] < 1e-9


def test_run_help_lists_every_kind(capsys):
    """`run --help` prints each kind's argv contract (a '%' in a contract once broke argparse)."""
    from recon_eval.runners.external import KINDS

    with pytest.raises(SystemExit) as e:
        main(["run", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert e.value.code == 0 and all(f"{k}: " in out for k in KINDS)
    assert "30 % outliers" in out
