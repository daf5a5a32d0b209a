"""``recon-eval normals`` on the first four images of scenes/photometric_stereo.yaml: frames,
objects, albedo and lights, the JSON a gate reads, and bad input (exit 2, the file named)."""
import json
from pathlib import Path

import numpy as np
import pytest

from recon_eval.cli import main
from scenegen.dataset import Dataset
from scenegen.geometry.conventions import DILIGENT_FROM_OPENCV_CAM
from scenegen.pipeline.run import render_spec

SCENE = Path(__file__).parents[3] / "scenes" / "photometric_stereo.yaml"
pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def ps(tmp_path_factory):
    out = tmp_path_factory.mktemp("ps4") / "ps"
    render_spec(SCENE, out, frames="0-3", spp=4, progress=False, show_warnings=False)
    return out


def _truth(ps, view="ps_0000"):
    d = Dataset(ps)
    return d.truth(view)["normals_cam"].astype(np.float64), d


def test_truth_scores_zero_in_its_frame_and_not_in_the_other(ps, tmp_path):
    n, _ = _truth(ps)
    np.save(tmp_path / "cv.npy", n)
    np.save(tmp_path / "dl.npy", n @ DILIGENT_FROM_OPENCV_CAM.T)
    for name, frame, zero in (("dl.npy", "diligent", True), ("cv.npy", "opencv", True), ("cv.npy", "diligent", False)):
        out = tmp_path / f"{name}_{frame}.json"
        assert main(["normals", str(tmp_path / name), str(ps), "--frame", frame, "-q", "--json", str(out)]) == 0
        r = json.load(open(out))["results"]["all.normals"]
        assert (r["mean_ae_deg"] < 0.05) == zero  # float32 truth: acos(1 - 6e-8) = 0.02 deg
        assert (r["within_10deg"] == 1.0) == zero


def test_planted_rotation_per_object_albedo_and_lights(ps, tmp_path):
    n, d = _truth(ps)
    a = np.radians(5.0)
    R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    est = np.where(np.isfinite(n), n @ R.T, 0.0) @ DILIGENT_FROM_OPENCV_CAM.T
    np.save(tmp_path / "n.npy", est)
    np.save(tmp_path / "albedo.npy", 3.0 * np.nan_to_num(d.albedo("ps_0000")))
    L = np.array([d.lights(v)[0].direction_to_light_cam for v in d.views]) @ R.T @ DILIGENT_FROM_OPENCV_CAM.T
    np.savetxt(tmp_path / "light_directions.txt", L)
    out = tmp_path / "r.json"
    assert main(["normals", str(tmp_path / "n.npy"), str(ps), "--object", "lambertian", "--albedo",
                 str(tmp_path / "albedo.npy"), "--lights", str(tmp_path / "light_directions.txt"), "-q",
                 "--json", str(out), "--method", "rotated"]) == 0
    doc = json.load(open(out))
    r = doc["results"]
    assert set(r) == {"all.normals", "lambertian.normals", "all.albedo", "lights"}
    assert r["lambertian.normals"]["mean_ae_deg"] <= 5.0 + 1e-6 and r["lambertian.normals"]["median_ae_deg"] > 2.0
    assert r["all.albedo"]["scale"] == pytest.approx(1 / 3) and r["all.albedo"]["rel_mae"] < 1e-6
    assert max(r["lights"]["per_light_deg"]) <= 5.0 + 1e-6
    assert doc["inputs"]["scene"] == "photometric_stereo" and doc["inputs"]["method"] == "rotated"
    gates = tmp_path / "g.yaml"
    gates.write_text("version: 1\ngates:\n  - {scene: photometric_stereo, method: rotated, metric: lambertian.normals.mean_ae_deg, op: '<=', threshold: 1.0}\n")
    assert main(["gate", str(gates), str(out)]) == 1


@pytest.mark.parametrize("case", ["shape", "object", "lights", "suffix"])
def test_bad_input_exits_2_naming_the_file(ps, tmp_path, capsys, case):
    n, d = _truth(ps)
    np.save(tmp_path / "n.npy", n)
    args = ["normals", str(tmp_path / "n.npy"), str(ps)]
    if case == "shape":
        np.save(tmp_path / "n.npy", n[1:])
        want = "n.npy"
    elif case == "object":
        args += ["--object", "teapot"]
        want = "teapot"
    elif case == "lights":
        (tmp_path / "L.txt").write_text("0 0 1\n0 0 1\n")
        args += ["--lights", str(tmp_path / "L.txt")]
        want = "L.txt"
    else:
        (tmp_path / "n.txt").write_text("0 0 1\n")
        args[1] = str(tmp_path / "n.txt")
        want = "n.txt"
    assert main(args) == 2
    err = capsys.readouterr().err
    assert want in err and "Traceback" not in err
