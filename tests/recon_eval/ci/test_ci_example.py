"""The files docs/ci.md's example workflow uses exist and agree with each other."""
from pathlib import Path

from recon_eval.cli import main

ROOT = Path(__file__).resolve().parents[3]


def test_example_gate_file_holds_on_the_stored_baseline(tmp_path, capsys):
    gates = ROOT / "gates/calib_checkerboard.yaml"
    baseline = ROOT / "baselines/calib_checkerboard.json"
    assert main(["gate", str(gates), str(baseline), "--baseline", str(baseline), "--margin", "0.2",
                 "--margin-abs", "0.005", "--junit", str(tmp_path / "gates.xml")]) == 0
    assert "10 of 10 gates hold" in capsys.readouterr().out
    assert (tmp_path / "gates.xml").read_text().count("<testcase") == 10


def _workflows():
    """(GitHub workflow, GitLab CI file) as docs/ci.md shows them."""
    import re

    import yaml

    text = (ROOT / "docs/ci.md").read_text()
    section = text[text.index("## Example CI workflows"):]
    blocks = [yaml.safe_load(b) for b in re.findall(r"```yaml\n(.*?)```", section, re.S)[:2]]
    return blocks[0], blocks[1]


def _runs(steps) -> list[str]:
    return [s["run"] for s in steps if "run" in s]


def test_the_documented_workflows_cache_the_venv_and_gate_without_the_test_suite(tmp_path, capsys, monkeypatch):
    import shlex

    gh, gl = _workflows()
    gate = gh["jobs"]["gate"]
    (cache,) = [s for s in gate["steps"] if s.get("uses", "").startswith("actions/cache@")]
    assert cache["with"]["path"] == ".venv" and "hashFiles('pyproject.toml')" in cache["with"]["key"]
    assert "python-version" in cache["with"]["key"]  # a venv is tied to its interpreter
    for script in (_runs(gate["steps"]), gl["accuracy-gate"]["script"]):
        assert "make setup" in script
        assert not any("make test" in r or "pytest" in r for r in script), script
        assert any("recon-eval gate" in r for r in script)
    assert gl["accuracy-gate"]["cache"]["paths"] == [".venv"]
    assert gl["accuracy-gate"]["cache"]["key"]["files"] == ["pyproject.toml"]
    assert gl["accuracy-gate"]["artifacts"]["reports"]["junit"] == "gates.xml"
    # both gate lines hold on the stored baseline (as the run's result) and agree with each other
    lines = [next(r for r in s if "recon-eval gate" in r) for s in (_runs(gate["steps"]), gl["accuracy-gate"]["script"])]
    argvs = [shlex.split(r.replace("\n", " ")) for r in lines]
    assert argvs[0] == argvs[1]
    argv = [a.replace("runs/calib/result.json", "baselines/calib_checkerboard.json") for a in argvs[0][1:]]
    argv[argv.index("--junit") + 1] = str(tmp_path / "gates.xml")
    monkeypatch.chdir(ROOT)
    assert main(argv) == 0
    assert "10 of 10 gates hold" in capsys.readouterr().out
