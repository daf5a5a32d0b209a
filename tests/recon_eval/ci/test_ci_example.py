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
