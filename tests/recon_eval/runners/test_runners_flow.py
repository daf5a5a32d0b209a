"""The OpenCV flow runners on the two-frame plane dataset (no Mitsuba): numbers against the truth."""
import numpy as np

from recon_eval.runners import run_method


def test_dis_and_farneback_flow(flow_dataset, tmp_path):
    root, _ = flow_dataset
    for name, epe in (("opencv-flow-dis", 2.0), ("opencv-flow-farneback", 1.0)):
        d = run_method(name, root, tmp_path / name)
        m = d["metrics"]
        assert (tmp_path / name / "flow" / "cam_000__cam_001.flo").is_file()
        assert 0 < m["epe_all_px"] < epe and np.isfinite(m["epe_noc_px"]), (name, m)


def test_lk_tracks(flow_dataset, tmp_path):
    root, _ = flow_dataset
    d = run_method("opencv-lk-tracks", root, tmp_path / "lk")
    m = d["metrics"]
    assert m["n_tracks"] > 100 and m["within_1px"] > 0.85 and m["epe_median_px"] < 0.6, m
    rows = np.loadtxt(tmp_path / "lk" / "tracks" / "cam_000__cam_001.txt")
    assert rows.shape[1] == 5 and np.all(rows[:, :2] == np.rint(rows[:, :2]))
