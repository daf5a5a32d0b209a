import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.readers.kitti_png import write_kitti_disparity
from recon_eval.readers.ply import write_point_cloud_ply

REPO = Path(__file__).resolve().parents[3]


def lattice(n=6):
    u, v = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    return np.c_[u.ravel(), v.ravel(), np.zeros(n * n)]


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


class TestCloud:
    def test_scores_and_json(self, tmp_path, capsys):
        write_point_cloud_ply(tmp_path / "gt.ply", lattice())
        write_point_cloud_ply(tmp_path / "rec.ply", lattice() + [0, 0, 0.25])
        code, out, _ = run(["cloud", tmp_path / "rec.ply", tmp_path / "gt.ply", "--tau", "0.25", "--tau", "0.3",
                            "--no-downsample", "--json", tmp_path / "r.json"], capsys)
        assert code == 0 and "tanks_and_temples" in out
        doc = json.loads((tmp_path / "r.json").read_text())
        assert doc["schema_version"] == "1.0" and doc["command"] == "cloud"
        assert doc["results"]["tanks_and_temples@0.25m"]["fscore"] == 0.0  # strict <
        assert doc["results"]["tanks_and_temples@0.3m"]["fscore"] == 1.0
        assert doc["results"]["eth3d@0.25m"]["f1"] == 1.0  # <=
        assert doc["results"]["chamfer"]["distance_rec_to_gt"] == "nearest_point"
        assert not list(tmp_path.glob(".r.json.*"))  # no temporary left behind

    def test_mesh_truth_is_sampled_and_declared(self, tmp_path, capsys):
        import trimesh

        trimesh.creation.box().export(tmp_path / "gt.ply")
        write_point_cloud_ply(tmp_path / "rec.ply", trimesh.creation.box().sample(2000, seed=0))
        code, _, _ = run(["cloud", tmp_path / "rec.ply", tmp_path / "gt.ply", "--gt-samples", "5000",
                          "--json", tmp_path / "r.json", "--quiet"], capsys)
        doc = json.loads((tmp_path / "r.json").read_text())
        assert code == 0 and doc["inputs"]["gt_is_mesh"] is True
        assert doc["results"]["chamfer"]["distance_rec_to_gt"] == "mesh_surface"
        assert doc["results"]["chamfer"]["rec_to_gt_mean_m"] < 1e-12

    def test_missing_file_is_exit_2_without_traceback(self, tmp_path, capsys):
        write_point_cloud_ply(tmp_path / "gt.ply", lattice())
        code, _, err = run(["cloud", tmp_path / "nope.ply", tmp_path / "gt.ply"], capsys)
        assert code == 2 and "nope.ply: no such file" in err and "Traceback" not in err


class TestOtherCommands:
    def test_disparity_kitti(self, tmp_path, capsys):
        gt = np.full((4, 5), 20.0)
        est = gt.copy()
        est[0, 0] = 30.0
        write_kitti_disparity(tmp_path / "gt.png", gt)
        write_kitti_disparity(tmp_path / "est.png", est)
        code, _, _ = run(["disparity", tmp_path / "est.png", tmp_path / "gt.png", "--json", tmp_path / "d.json"], capsys)
        doc = json.loads((tmp_path / "d.json").read_text())
        assert code == 0 and doc["results"]["kitti_d1"]["d1_all_occ_pct"] == pytest.approx(5.0)

    def test_depth_wrong_shape_is_exit_2(self, tmp_path, capsys):
        np.save(tmp_path / "est.npy", np.ones((3, 3, 2)))
        np.save(tmp_path / "gt.npy", np.ones((3, 3)))
        code, _, err = run(["depth", tmp_path / "est.npy", tmp_path / "gt.npy"], capsys)
        assert code == 2 and "est.npy: expected an array of shape (N, N), got (3, 3, 2)" in err

    def test_fmatrix_degenerate_is_scored_not_crashed(self, tmp_path, capsys):
        np.save(tmp_path / "m.npy", np.array([[1.0, 2, 3, 4], [5, 6, 7, 8]]))
        (tmp_path / "F.txt").write_text("nan 0 0\n0 0 0\n0 0 0\n")
        code, _, _ = run(["fmatrix", tmp_path / "F.txt", "--matches", tmp_path / "m.npy", "--json", tmp_path / "f.json"], capsys)
        doc = json.loads((tmp_path / "f.json").read_text())
        assert code == 0 and doc["results"]["fundamental"]["failed"] is True
        assert doc["results"]["fundamental"]["sampson_rms_px"] == "inf"

    def test_homography(self, tmp_path, capsys):
        (tmp_path / "H.txt").write_text("1 0 0\n0 1 0\n0 0 1\n")
        (tmp_path / "G.txt").write_text("1 0 3\n0 1 4\n0 0 1\n")
        code, _, _ = run(["homography", tmp_path / "H.txt", tmp_path / "G.txt", "--size", 64, 48,
                          "--json", tmp_path / "h.json"], capsys)
        doc = json.loads((tmp_path / "h.json").read_text())
        assert code == 0 and doc["results"]["homography"]["mace_px"] == 5.0

    def test_poses_tum(self, tmp_path, capsys):
        lines = [f"{k}.0 {np.cos(k)} {np.sin(k)} {0.1 * k} 0 0 0 1" for k in range(6)]
        (tmp_path / "gt.txt").write_text("\n".join(lines) + "\n")
        (tmp_path / "est.txt").write_text("\n".join(lines[:5]) + "\n")
        code, _, _ = run(["poses", tmp_path / "est.txt", tmp_path / "gt.txt", "--json", tmp_path / "p.json"], capsys)
        doc = json.loads((tmp_path / "p.json").read_text())
        assert code == 0
        assert doc["results"]["ape"]["registration_ratio"] == pytest.approx(5 / 6)
        assert doc["results"]["ape"]["trans_err_m"][5] == "inf"
        assert doc["results"]["ape"]["trans_stats_m"]["max"] < 1e-9

    def test_bad_usage_is_exit_2(self, capsys):
        with pytest.raises(SystemExit) as exc:
            main(["cloud"])
        assert exc.value.code == 2


def test_help_is_fast_and_imports_no_mitsuba():
    code = (
        "import sys, time; t = time.perf_counter()\n"
        "import recon_eval.cli, recon_eval.cli.registry, recon_eval.metrics.pointcloud, recon_eval.metrics.poses, "
        "recon_eval.metrics.stereo, recon_eval.metrics.depth, recon_eval.metrics.epipolar, "
        "recon_eval.metrics.calibration, recon_eval.metrics.pnp, recon_eval.metrics.align\n"
        "assert not any(m.split('.')[0] in ('mitsuba', 'drjit') for m in sys.modules), 'mitsuba imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=REPO)
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "recon_eval", "--help"], cwd=REPO, capture_output=True, text=True)
    assert res.returncode == 0 and "cloud" in res.stdout
    assert time.perf_counter() - t0 < 1.0


def test_poses_colmap_models(tmp_path, capsys, write_colmap):
    from scipy.spatial.transform import Rotation

    qs = Rotation.random(4, random_state=3).as_quat(scalar_first=True)
    ts = np.random.default_rng(2).normal(size=(4, 3))
    write_colmap(tmp_path / "gt", qs, ts)
    write_colmap(tmp_path / "est", qs[:3], ts[:3])
    code, _, _ = run(["poses", tmp_path / "est", tmp_path / "gt", "--json", tmp_path / "p.json"], capsys)
    doc = json.loads((tmp_path / "p.json").read_text())
    assert code == 0 and doc["inputs"]["format"] == "colmap"
    assert doc["results"]["ape"]["registration_ratio"] == 0.75
    assert doc["results"]["ape"]["rot_stats_deg"]["max"] < 1e-6


@pytest.mark.parametrize("command", [["homography", "{f}", "{f}", "--size", "8", "8"], ["poses", "{f}", "{f}"],
                                     ["fmatrix", "{f}", "--matches", "{f}"], ["depth", "{f}", "{f}"],
                                     ["cloud", "{f}", "{f}"]])
def test_binary_garbage_is_exit_2(tmp_path, capsys, command):
    f = tmp_path / ("junk.npy" if command[0] in ("depth",) else "junk.txt")
    f.write_bytes(bytes(range(256)) * 4)
    if command[0] == "cloud":
        f = f.rename(tmp_path / "junk.ply")
    code, _, err = run([c.format(f=f) for c in command], capsys)
    assert code == 2 and "junk" in err and "Traceback" not in err
