"""A rendered sequence scored end to end: `recon-eval tracks` on the truth and on altered
predictions (values worked by hand), the LK track baseline and DIS flow as methods (the flow's
truth and occlusion states from the sequence's motion truth, moving objects included)."""
import json
from pathlib import Path

import numpy as np
import pytest

from recon_eval.cli import main as recon_main
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.runners import run_method
from scenegen.cli import main as scenegen_main
from scenegen.dataset import Dataset
from scenegen.dataset.codecs import encode_npz
from scenegen.dataset.crossview import VISIBLE

pytestmark = pytest.mark.render

SPEC = """
name: seq_eval
render: {spp: 8, max_depth: 2}
sequence: {fps: 20, frames: 4, flow_steps: [1], tracks: {count: 40, query_frames: [0]}}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: natural, params: {size_px: 256}}}
  - name: cube
    shape: {type: box, size: [0.4, 0.4, 0.4]}
    material: {type: diffuse, texture: {type: noise, params: {octaves: 4}}}
    trajectory:
      keyframes:
        - {time_s: 0.0, translation: [-0.25, 0, 0.2]}
        - {time_s: 0.15, translation: [0.2, 0.05, 0.2], rotation_deg: [0, 0, 20]}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [96, 72], fx: 80}
views:
  - camera: cam
    trajectory:
      keyframes:
        - {time_s: 0.0, eye: [0, -2, 1.8], target: [0, 0, 0]}
        - {time_s: 0.15, eye: [0.1, -2, 1.8], target: [0, 0, 0]}
"""


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    d = tmp_path_factory.mktemp("seq_eval")
    (d / "scene.yaml").write_text(SPEC)
    assert scenegen_main(["render", str(d / "scene.yaml"), "-o", str(d / "ds"), "-q"]) == 0
    return d / "ds"


def _score(tmp_path, sequence, tracks, occluded, *extra):
    (tmp_path / "pred.npz").write_bytes(encode_npz({"tracks_xy": tracks, "occluded": occluded}))
    out = tmp_path / "r.json"
    assert recon_main(["tracks", str(tmp_path / "pred.npz"), str(sequence), "--json", str(out), "-q", *extra]) == 0
    return json.loads(out.read_text())["results"]


def test_the_truth_scores_one_and_known_errors_score_as_worked_out(sequence, tmp_path):
    ds = read_dataset(sequence)
    (stream,) = ds.track_streams()
    truth = ds.tracks_truth(stream)
    vis_after = ~truth.occluded[:, 1:]
    assert vis_after.sum() > 60 and truth.occluded.sum() > 0  # points to score, and some occluded
    r = _score(tmp_path, sequence, truth.tracks_xy, truth.occluded)[stream]
    assert (r["average_jaccard"], r["average_pts_within"], r["occlusion_accuracy"]) == (1.0, 1.0, 1.0)
    shifted = truth.tracks_xy + np.float32([2.5, 0.0])  # 2.5 px at the native resolution
    r = _score(tmp_path, sequence, shifted, truth.occluded, "--native-resolution")[stream]
    assert [r["pts_within"][k] for k in ("1", "2", "4", "8", "16")] == [0.0, 0.0, 1.0, 1.0, 1.0]
    assert r["occlusion_accuracy"] == 1.0
    r = _score(tmp_path, sequence, truth.tracks_xy, ~truth.occluded)[stream]
    assert r["occlusion_accuracy"] == 0.0 and r["average_jaccard"] == 0.0


def test_a_stream_without_predictions_is_named(sequence, tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    assert recon_main(["tracks", str(tmp_path / "empty"), str(sequence)]) == 2
    assert "no predictions for stream" in capsys.readouterr().err


def test_lk_tracks_and_dis_flow_run_as_methods(sequence, tmp_path):
    doc = run_method("opencv-lk-tapvid", sequence, tmp_path / "lk")
    m = doc["metrics"]
    assert 0.3 < m["average_pts_within"] <= 1.0 and 0.0 < m["average_jaccard"] <= 1.0
    assert 0.5 < m["occlusion_accuracy"] <= 1.0
    assert (tmp_path / "lk" / "tracks").is_dir()
    ds = read_dataset(sequence)
    a, b = ds.flow_pairs()[0]
    flow, states, source = ds.flow_truth(a, b)
    assert source.startswith("sequence/motion/") and states is not None
    assert (states == VISIBLE).sum() > 0 and (states != VISIBLE).sum() > 0
    flo = Dataset(sequence).sequence.flow(a, b).astype(np.float64)  # the .flo file of the same pair
    both = np.isfinite(flow[..., 0]) & np.isfinite(flo[..., 0])
    assert both.sum() > 1000 and np.abs(flow[both] - flo[both]).max() < 1e-4
    doc = run_method("opencv-flow-dis", sequence, tmp_path / "dis")
    assert np.isfinite(doc["metrics"]["epe_noc_px"]) and np.isfinite(doc["metrics"]["epe_all_px"])


EST = Path(__file__).resolve().parent / "estimators"


def _external(name, kind, command, sequence, out):
    from recon_eval.runners.declared import external_method

    return run_method(name, sequence, out, declared={name: external_method(name, kind, command)})


def test_external_tracks_kind_equals_the_builtin_lk(sequence, tmp_path):
    mine = _external("my-lk", "tracks", f"{{python}} {EST / 'lk_tracks.py'} {{queries}} {{out}} {{images}}", sequence,
                     tmp_path / "mine")
    ref = run_method("opencv-lk-tapvid", sequence, tmp_path / "ref")
    assert mine["metrics"] == ref["metrics"] and mine["inputs"]["task"] == ref["inputs"]["task"]
    assert set(mine["metrics"]) == {"average_jaccard", "average_pts_within", "occlusion_accuracy"}


ARC = """
name: arc
render: {spp: 4, max_depth: 2}
sequence: {fps: 10, frames: 5}
objects:
  - {name: floor, shape: {type: plane, size: [3, 3]}, material: {type: diffuse, texture: {type: noise}}}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [32, 24], fx: 28}
views:
  - camera: cam
    trajectory:
      keyframes:
        - {time_s: 0.0, eye: [0, -2, 1.8], target: [0, 0, 0]}
        - {time_s: 0.2, eye: [0.6, -1.8, 1.6], target: [0, 0, 0]}
        - {time_s: 0.4, eye: [1.0, -1.2, 1.9], target: [0, 0, 0]}
"""


def test_external_trajectory_kind_and_recon_eval_poses_agree(sequence, tmp_path):
    """The truth trajectory scaled by 2: APE 0 after Sim(3), every frame registered; the TUM export's
    groundtruth against the same file with ``recon-eval poses --json``: the same numbers, same names.
    A straight truth path (the module's sequence) cannot anchor Sim(3): not applicable, said."""
    cmd = f"{{python}} {EST / 'true_trajectory.py'} {{dataset}} {{times}} {{out}} 2"
    from recon_eval.errors import NotApplicable
    with pytest.raises(NotApplicable, match="cannot anchor a Sim"):
        _external("my-vo", "trajectory", cmd, sequence, tmp_path / "line")
    (tmp_path / "arc.yaml").write_text(ARC)
    sequence = tmp_path / "arc"
    assert scenegen_main(["render", str(tmp_path / "arc.yaml"), "-o", str(sequence), "-q"]) == 0
    doc = _external("my-vo", "trajectory", cmd, sequence, tmp_path / "vo")
    m = doc["metrics"]
    assert m["registration_ratio"] == 1.0 and m["max_rot_err_deg"] < 1e-5 and m["ape_trans_rmse_m"] < 1e-6
    assert doc["inputs"]["task"] == "camera trajectory"
    assert scenegen_main(["export", str(sequence), "--format", "tum", "-o", str(tmp_path / "tum"), "-q"]) == 0
    gt = next((tmp_path / "tum").glob("*/groundtruth.txt"))
    est = next((tmp_path / "vo").glob("*/trajectory.txt"))
    assert recon_main(["poses", str(est), str(gt), "--json", str(tmp_path / "p.json"), "-q"]) == 0
    assert json.loads((tmp_path / "p.json").read_text())["metrics"] == pytest.approx(m, abs=1e-9)
