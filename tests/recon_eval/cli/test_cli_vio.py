"""``recon-eval poses`` on timestamped trajectories: evo's association (max difference, offset)
gives evo's APE; the VIO figures (rpg absolute and relative errors, drift per time, ov_eval NEES
from an estimate with covariances) land in the report; bad lines are refused."""
import json

import numpy as np
import pytest
from evo.core import metrics, sync
from evo.tools import file_interface
from scipy.spatial.transform import Rotation

from recon_eval.cli import main


def run(argv):
    return main([str(a) for a in argv] + ["--quiet"])


def _lines(t, c, R, cov=None):
    q = Rotation.from_matrix(R).as_quat()  # x y z w, world_from_cam
    rows = []
    for k in range(len(t)):
        v = [t[k], *c[k], *q[k]] + ([] if cov is None else list(cov[k]))
        rows.append(" ".join(f"{x:.17g}" for x in v) + "\n")
    return "".join(rows)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("vio")
    rng = np.random.default_rng(7)
    t = 100.0 + np.arange(200) * 0.05
    s = t - t[0]
    c = np.stack([np.cos(0.5 * s) * 3, np.sin(0.5 * s) * 2, 0.2 * s], 1)
    R = Rotation.from_euler("ZYX", np.stack([0.5 * s, 0.1 * np.sin(s), 0.05 * s], 1)).as_matrix()
    (d / "gt.txt").write_text(_lines(t, c, R))
    # the estimate at its own 30 Hz clock, 0.02 s late, drifting; ov_eval's covariance columns
    te = 100.0 + np.arange(320) * (1 / 30) + 0.02
    se = te - 0.02 - t[0]
    ce = np.stack([np.cos(0.5 * se) * 3, np.sin(0.5 * se) * 2, 0.2 * se], 1)
    ce = ce + np.cumsum(rng.normal(0, 0.01, (320, 3)), 0)
    Re = Rotation.from_euler("ZYX", np.stack([0.5 * se, 0.1 * np.sin(se), 0.05 * se], 1)).as_matrix()
    upper = np.tile([1e-4, 0, 0, 1e-4, 0, 1e-4, 4e-4, 0, 0, 4e-4, 0, 4e-4], (320, 1))
    (d / "est.txt").write_text(_lines(te, ce, Re))
    (d / "est_cov.txt").write_text(_lines(te, ce, Re, upper))
    return d


def test_evo_association_with_offset_gives_evos_ape(files, tmp_path):
    out = tmp_path / "r.json"
    assert run(["poses", files / "est.txt", files / "gt.txt", "--t_offset", "-0.02", "--t_max_diff", "0.02",
                "--alignment", "se3", "--json", out]) == 0
    r = json.loads(out.read_text())["results"]
    ref = file_interface.read_tum_trajectory_file(str(files / "gt.txt"))
    est = file_interface.read_tum_trajectory_file(str(files / "est.txt"))
    ref, est = sync.associate_trajectories(ref, est, max_diff=0.02, offset_2=-0.02)
    est.align(ref, correct_scale=False)
    ape = metrics.APE(metrics.PoseRelation.translation_part)
    ape.process_data((ref, est))
    stats = ape.get_all_statistics()
    assert r["ape"]["n_registered"] == ref.num_poses == r["vio"]["n_associated"]
    assert abs(r["ape"]["trans_stats_m"]["rmse"] - stats["rmse"]) < 1e-12
    assert abs(r["ape"]["trans_stats_m"]["max"] - stats["max"]) < 1e-12
    vio = r["vio"]
    assert vio["offset_s"] == -0.02 and vio["nees"] is None
    assert len(vio["relative_per_distance"]) == 5 and len(vio["drift_per_time"]) == 5
    first = next(iter(vio["drift_per_time"].values()))
    assert first["unit"] == "s" and first["trans_stats_m"]["n"] > 10


def test_nees_from_ov_eval_covariance_columns(files, tmp_path):
    out = tmp_path / "r.json"
    assert run(["poses", files / "est_cov.txt", files / "gt.txt", "--t_offset", "-0.02", "--t_max_diff", "0.02",
                "--rpg-alignment", "posyaw", "--rpg-n-aligned", "1", "--json", out]) == 0
    vio = json.loads(out.read_text())["results"]["vio"]
    assert vio["nees"]["alignment"] == "posyaw" and vio["absolute"]["n_aligned"] == 1
    assert np.isfinite(vio["nees"]["mean_ori"]) and np.isfinite(vio["nees"]["mean_pos"])


def test_mixed_line_lengths_are_refused(files, tmp_path, capsys):
    lines = (files / "est_cov.txt").read_text().splitlines()
    bad = tmp_path / "bad.txt"
    bad.write_text(lines[0] + "\n" + " ".join(lines[1].split()[:8]) + "\n")
    assert run(["poses", bad, files / "gt.txt"]) == 2
    err = capsys.readouterr().err
    assert "bad.txt:2: expected 20 numbers as the lines above" in err and "Traceback" not in err


def test_a_bad_euroc_groundtruth_row_is_refused(files, tmp_path, capsys):
    bad = tmp_path / "data.csv"
    bad.write_text("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []\n"
                   "100000000000,0,0,0,1,0,0,0\n100050000000,0,0,x,1,0,0,0\n")
    assert run(["poses", files / "est.txt", bad]) == 2
    err = capsys.readouterr().err
    assert "data.csv:3: not an integer timestamp and numbers" in err and "Traceback" not in err
