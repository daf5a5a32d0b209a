"""Gate files: every error of a bad gate file names file:line: field, exits 2 without a traceback
(the located-YAML layer, scenegen.located_yaml); duplicate keys are refused."""
import subprocess
import sys
from pathlib import Path

import pytest

from recon_eval.ci.gates import load_gates
from recon_eval.errors import InputError

ROOT = Path(__file__).resolve().parents[3]


def _gate(*args):
    return subprocess.run([sys.executable, "-m", "recon_eval", "gate", *map(str, args)], capture_output=True,
                          text=True, cwd=ROOT)


@pytest.mark.parametrize("text, expect", [
    ("version: 1\ngates:\n  - {method: m, metric: x, op: '<~', threshold: 1}\n", "g.yaml:3: gates[0].op"),
    ("version: 1\ngates:\n  - method: m\n    metric: x\n    op: '<'\n", "g.yaml:3: gates[0].threshold: missing"),
    ("version: 1\ngates:\n  - {method: m, metric: x, op: '<', threshold: abc}\n", "gates[0].threshold: expected a finite"),
    ("version: 2\ngates: []\n", "version: expected 1"),
    ("gates: [\n", "invalid YAML"),
])
def test_bad_gate_file_exit_2_names_line_and_field(tmp_path, text, expect):
    f = tmp_path / "g.yaml"
    f.write_text(text)
    r = _gate(f, f)
    assert r.returncode == 2 and expect in r.stderr and "Traceback" not in r.stderr


def test_gate_file_fields_and_lines(tmp_path):
    f = tmp_path / "g.yaml"
    f.write_text("version: 1\ngates:\n  - {method: m, metric: x, op: '<=', threshold: 1e-3}\n"
                 "  - scene: s\n    method: m2\n    metric: y\n    op: '>'\n    threshold: 2\n    reason: why\n")
    g = load_gates(f)
    assert [(x.scene, x.method, x.metric, x.op, x.threshold, x.reason) for x in g] == [
        ("*", "m", "x", "<=", 1e-3, ""), ("s", "m2", "y", ">", 2.0, "why")]
    assert [x.where for x in g] == [f"{f}:3", f"{f}:4"]


@pytest.mark.parametrize("text, expect", [
    ("version: 1\ngates:\n  - {method: m, metric: x, op: '<', threshold: 1, method: n}\n", "g.yaml:3: gates[0].method: duplicate key"),
    ("version: 1\ngates:\n  - {method: m, metric: x, op: '<', threshold: 1, treshold: 2}\n", "unknown key 'treshold'"),
    ("version: 1\ngates: []\n", "g.yaml:2: gates: expected a non-empty list"),
    ("[1, 2]\n", "g.yaml:1: expected a mapping with 'version' and 'gates'"),
])
def test_more_bad_gate_files(tmp_path, text, expect):
    f = tmp_path / "g.yaml"
    f.write_text(text)
    with pytest.raises(InputError) as e:
        load_gates(f)
    assert expect in str(e.value)
