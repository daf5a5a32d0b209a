"""``recon-eval flow`` against a dataset's flow and occlusion states, and against flow files."""
import json

import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.readers.flow import read_flow, write_kitti_flow
from recon_eval.readers.scenegen_dataset import read_dataset
from scenegen.dataset.codecs import encode_flo, write_npy


def run(argv):
    return main([str(a) for a in argv] + ["--quiet"])


def test_exact_flow_scores_zero_and_splits_occlusions(flow_dataset, tmp_path):
    root, _ = flow_dataset
    g, st, source = read_dataset(root).flow_truth("cam_000", "cam_001")
    assert source.endswith("cam_000/cam_001.flo") and st is not None
    (tmp_path / "e.flo").write_bytes(encode_flo(g))
    assert run(["flow", tmp_path / "e.flo", root, "--views", "cam_000", "cam_001", "--json", tmp_path / "r.json"]) == 0
    r = json.loads((tmp_path / "r.json").read_text())["results"]["flow"]
    assert r["epe_all_px"] < 1e-5 and r["fl_all_all_pct"] == 0.0 and r["density_pct"] == 100.0
    assert r["n_px_occ"] > 0 and r["n_px_noc"] + r["n_px_occ"] == r["n_px"] and r["occlusion_truth"]


def test_a_planted_shift_is_its_epe(flow_dataset, tmp_path):
    root, _ = flow_dataset
    g, _, _ = read_dataset(root).flow_truth("cam_001", "cam_000")
    write_npy(tmp_path / "e.npy", g + [0.6, -0.8])  # |(0.6, -0.8)| = 1 px
    assert run(["flow", tmp_path / "e.npy", root, "--views", "cam_001", "cam_000", "--json", tmp_path / "r.json"]) == 0
    r = json.loads((tmp_path / "r.json").read_text())["results"]["flow"]
    assert r["epe_all_px"] == pytest.approx(1.0, abs=1e-5) and r["epe_noc_px"] == pytest.approx(1.0, abs=1e-5)


def test_a_folder_scores_every_flow_pair_and_counts_missing_ones(flow_dataset, tmp_path):
    root, _ = flow_dataset
    g, _, _ = read_dataset(root).flow_truth("cam_000", "cam_001")
    (tmp_path / "est").mkdir()
    write_kitti_flow(tmp_path / "est" / "cam_000__cam_001.png", g)
    assert run(["flow", tmp_path / "est", root, "--json", tmp_path / "r.json"]) == 0
    d = json.loads((tmp_path / "r.json").read_text())
    assert d["inputs"]["pairs"] == ["cam_000__cam_001", "cam_001__cam_000"]
    assert d["inputs"]["pairs_without_estimate"] == ["cam_001__cam_000"]
    assert d["results"]["flow"]["density_pct"] == pytest.approx(50.0, abs=1.0)


def test_file_truth_with_a_noc_file(tmp_path):
    rng = np.random.default_rng(0)
    g = rng.normal(0, 5, (10, 12, 2))
    noc = g.copy()
    noc[:, :4] = np.nan  # occluded columns
    for name, f in (("g.flo", g), ("noc.flo", noc), ("e.flo", g + [3.0, 4.0])):
        (tmp_path / name).write_bytes(encode_flo(f))
    assert run(["flow", tmp_path / "e.flo", tmp_path / "g.flo", "--gt-noc", tmp_path / "noc.flo",
                "--json", tmp_path / "r.json"]) == 0
    r = json.loads((tmp_path / "r.json").read_text())["results"]["flow"]
    assert r["epe_all_px"] == pytest.approx(5.0, abs=1e-5) and r["n_px_occ"] == 40


def test_bad_input_exits_2(flow_dataset, tmp_path):
    root, _ = flow_dataset
    (tmp_path / "e.flo").write_bytes(encode_flo(np.zeros((3, 3, 2))))
    assert run(["flow", tmp_path / "e.flo", root, "--views", "cam_000", "cam_001"]) == 2  # wrong shape
    assert run(["flow", tmp_path / "e.flo", root]) == 2  # a single file needs --views
    (tmp_path / "x.txt").write_text("x")
    assert run(["flow", tmp_path / "x.txt", tmp_path / "e.flo"]) == 2


def test_readers_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    f = rng.normal(0, 10, (6, 7, 2))
    f[2, 3] = np.nan
    write_kitti_flow(tmp_path / "f.png", f)
    back = read_flow(tmp_path / "f.png")
    assert np.isnan(back[2, 3]).all() and np.nanmax(np.abs(back - f)) <= 1 / 64
    write_npy(tmp_path / "f.npy", np.dstack([np.nan_to_num(f), np.isfinite(f[..., 0])]))
    assert np.isnan(read_flow(tmp_path / "f.npy")[2, 3]).all()
