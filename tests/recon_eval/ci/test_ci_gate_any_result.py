"""`recon-eval gate` on the JSON of every scoring command (not only `run`'s): one metric-path
scheme (recon_eval.ci.metric_paths), fnmatch wildcards for method, scene and command, the
`results.` prefix accepted only when unambiguous, and errors naming file:line."""
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.ci.gates import evaluate, load_gates, load_results
from recon_eval.ci.metric_paths import resolve
from recon_eval.cli import main
from recon_eval.errors import InputError


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def gate_file(tmp_path, *gates, name="g.yaml"):
    f = tmp_path / name
    f.write_text("version: 1\ngates:\n" + "".join(f"  - {g}\n" for g in gates))
    return f


@pytest.fixture()
def pnp_json(plane_dataset, tmp_path, capsys):
    """`recon-eval pnp` JSON of a pose 0.5 deg off the truth of free_000, labelled --method my-pnp."""
    root, cams = plane_dataset
    pose = cams["free_000"][1]
    dR = Rotation.from_rotvec([0.0, np.radians(0.5), 0.0]).as_matrix()
    (tmp_path / "p.json").write_text(json.dumps({"R": (dR @ pose.R).tolist(), "t": pose.t.tolist()}))
    code, _, err = run(["pnp", tmp_path / "p.json", root, "--view", "free_000", "--method", "my-pnp",
                        "--json", tmp_path / "pnp.json", "--quiet"], capsys)
    assert code == 0, err
    return tmp_path / "pnp.json"


def test_scored_json_carries_method_and_dataset_scene(pnp_json, plane_dataset):
    from recon_eval.readers.scenegen_dataset import read_dataset

    inputs = json.loads(pnp_json.read_text())["inputs"]
    assert inputs["method"] == "my-pnp" and inputs["scene"] == read_dataset(plane_dataset[0]).scene_name


def test_gate_holds_and_fails_on_a_pnp_json(pnp_json, tmp_path, capsys):
    ok = gate_file(tmp_path, "{method: 'my-*', scene: '*', metric: pnp.rot_err_deg, op: '<=', threshold: 0.6}",
                   "{method: '*', command: pnp, metric: results.pnp.rot_err_deg, op: '>', threshold: 0.4}")
    code, out, _ = run(["gate", ok, pnp_json], capsys)
    assert code == 0 and "2 of 2 gates hold" in out, out
    bad = gate_file(tmp_path, "{method: my-pnp, metric: pnp.rot_err_deg, op: '<', threshold: 0.1}", name="b.yaml")
    code, out, _ = run(["gate", bad, pnp_json, "--junit", tmp_path / "j.xml"], capsys)
    assert code == 1
    line = next(ln for ln in out.splitlines() if ln.startswith("FAIL"))
    assert "pnp.rot_err_deg = 0.5," in line and "threshold < 0.1" in line and f"{bad}:3" in line
    assert 'failures="1"' in (tmp_path / "j.xml").read_text()


def test_wildcards_are_patterns_not_literals(pnp_json, tmp_path):
    results = load_results([pnp_json])
    for pattern, matches in (("*", True), ("my-?np", True), ("my-[pq]np", True), ("other*", False)):
        g = gate_file(tmp_path, f"{{method: '{pattern}', metric: pnp.rot_err_deg, op: '<', threshold: 1}}")
        (o,) = evaluate(load_gates(g), results)
        assert o.passed is matches and (o.value is not None) is matches, (pattern, o.message)
    g = gate_file(tmp_path, "{method: '*', command: fmatrix, metric: pnp.rot_err_deg, op: '<', threshold: 1}")
    (o,) = evaluate(load_gates(g), results)
    assert not o.passed and "no result" in o.message and "command 'fmatrix'" in o.message


def test_unlabelled_result_matches_only_star(tmp_path, capsys):
    """A file-truth command without --method: only method '*' gates it (no silent match)."""
    H = np.array([[1.0, 0.01, 2.0], [0.0, 1.02, -1.0], [1e-5, 0.0, 1.0]])
    np.savetxt(tmp_path / "H.txt", H)
    Hn = H.copy()
    Hn[0, 2] += 0.5  # the estimate: every corner moved 0.5 px in x (up to the projective division)
    np.savetxt(tmp_path / "He.txt", Hn)
    code, _, err = run(["homography", tmp_path / "He.txt", tmp_path / "H.txt", "--size", "64", "48",
                        "--json", tmp_path / "h.json", "--quiet"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "h.json").read_text())
    assert "method" not in doc["inputs"] and "scene" not in doc["inputs"]
    mace = doc["results"]["homography"]["mace_px"]
    assert 0.49 < mace < 0.51
    star = gate_file(tmp_path, "{method: '*', metric: homography.mace_px, op: '<=', threshold: 0.6}")
    named = gate_file(tmp_path, "{method: x, metric: homography.mace_px, op: '<=', threshold: 0.6}", name="n.yaml")
    assert run(["gate", star, tmp_path / "h.json"], capsys)[0] == 0
    code, out, _ = run(["gate", named, tmp_path / "h.json"], capsys)
    assert code == 1 and "no result for scene '*' method 'x'" in out


def test_metric_path_scheme():
    doc = {"command": "fmatrix", "inputs": {}, "metrics": {"synthetic.sampson_rms_px": 0.25},
           "results": {"fundamental": {"sampson_rms_px": 0.5, "per_view": [1.0, "inf"], "note": "text"},
                       "eth3d@0.01m": {"f1": 0.75}}}
    assert resolve(doc, "synthetic.sampson_rms_px").value == 0.25  # a headline key (dots inside)
    assert resolve(doc, "fundamental.sampson_rms_px").value == 0.5
    assert resolve(doc, "results.fundamental.sampson_rms_px").value == 0.5  # the prefixed form: unambiguous
    assert resolve(doc, "metrics.synthetic.sampson_rms_px").value == 0.25
    assert resolve(doc, "fundamental.per_view.1").value == float("inf")
    assert resolve(doc, "eth3d@0.01m.f1").value == 0.75
    miss = resolve(doc, "fundamental.sampson_rms")
    assert miss.value is None and "did you mean 'fundamental.sampson_rms_px'" in miss.problem
    assert "not a number" in resolve(doc, "fundamental.note").problem
    amb = {"command": "x", "results": {"results": {"a": 1.0}, "a": 2.0}}
    look = resolve(amb, "results.a")
    assert look.value is None and "ambiguous" in look.problem and "write 'a'" in look.problem
    clash = {"command": "x", "results": {"a.b": {"c": 1.0}, "a": {"b.c": 2.0}}}
    assert "more than one value" in resolve(clash, "a.b.c").problem


def test_missing_metric_fails_with_the_right_path(pnp_json, tmp_path, capsys):
    g = gate_file(tmp_path, "{method: '*', metric: pnp.rot_err, op: '<', threshold: 1}")
    code, out, _ = run(["gate", g, pnp_json], capsys)
    assert code == 1 and "did you mean 'pnp.rot_err_deg'" in out and f"{g}:3" in out


def test_non_result_json_and_bad_gate_field(tmp_path, capsys):
    (tmp_path / "x.json").write_text('{"hello": 1}')
    g = gate_file(tmp_path, "{method: '*', metric: a, op: '<', threshold: 1}")
    code, _, err = run(["gate", g, tmp_path / "x.json"], capsys)
    assert code == 2 and "x.json: expected a recon-eval result JSON" in err
    (tmp_path / "y.json").write_text('{"command": "fmatrix",\n "results": [1, 2')
    code, _, err = run(["gate", g, tmp_path / "y.json"], capsys)
    assert code == 2 and "y.json:2: invalid JSON" in err
    bad = gate_file(tmp_path, "{method: '*', metric: a, op: '<', threshold: 1}",
                    "{method: '*', command: [1], metric: a, op: '<', threshold: 1}", name="c.yaml")
    with pytest.raises(InputError) as e:
        load_gates(bad)
    assert f"{bad}:4: gates[1].command" in str(e.value)
    empty = gate_file(tmp_path, "{method: '*', metric: '', op: '<', threshold: 1}", name="e.yaml")
    with pytest.raises(InputError) as e:
        load_gates(empty)
    assert f"{empty}:3: gates[0].metric: expected a metric path" in str(e.value)


def test_baseline_compares_the_same_command_method_scene(pnp_json, tmp_path, capsys):
    doc = json.loads(pnp_json.read_text())
    doc["results"]["pnp"]["rot_err_deg"] = 0.8
    (tmp_path / "worse.json").write_text(json.dumps(doc))
    g = gate_file(tmp_path, "{method: 'my-*', metric: pnp.rot_err_deg, op: '<=', threshold: 1}")
    code, out, _ = run(["gate", g, tmp_path / "worse.json", "--baseline", pnp_json, "--margin", "0.1"], capsys)
    assert code == 1 and "vs baseline 0.5: worse by 0.3" in out
