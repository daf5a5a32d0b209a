"""Every case of the malformed estimator-output corpus (tests/hostile/output_corpus.py) through
``recon_eval.cli.main``: the expected exit code and message fragment, one line, no traceback."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import run_cli  # noqa: E402
from output_corpus import CAL, CASES, GOOD_POSE, H_GOOD, TUM_OK, G, npy_bytes  # noqa: E402

from recon_eval.cli import main  # noqa: E402

KITTI_OK = "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.1 0 1 0 0 0 0 1 0\n"
RESULT = {"schema_version": 1, "command": "run", "inputs": {"scene": "s", "method": "m"}, "metrics": {"rmse_m": 0.01}}


def write(path: Path, content) -> None:
    if content is None:
        path.mkdir()
    elif isinstance(content, bytes):
        path.write_bytes(content)
    elif isinstance(content, str):
        if content != "<absent>":
            path.write_text(content)
    else:
        path.write_text(json.dumps(content))


def argv_of(command, cid, f: Path, d: Path, extra) -> list:
    """The command line of a case: its file in the estimate's (or truth's, gate's) place."""
    out = ["--json", d / "out.json", "--quiet"]
    if command == "pnp":
        write(d / "gt.json", GOOD_POSE)
        return ["pnp", f, d / "gt.json", *out]
    if command == "homography":
        write(d / "good.txt", H_GOOD)
        est, gt = (d / "good.txt", f) if f.name.startswith("gt") else (f, d / "good.txt")
        return ["homography", est, gt, *(extra or ("--size", "80", "60")), *out]
    if command == "poses":
        write(d / "gt.txt", KITTI_OK if cid.startswith("kitti") else TUM_OK)
        return ["poses", f, d / "gt.txt", *out]
    if command == "depth":
        write(d / "gt.npy", npy_bytes(np.full((6, 8), 2.0)))
        return ["depth", f, d / "gt.npy", *out]
    if command == "calibration":
        write(d / "gt.yaml", CAL.format(d=""))
        return ["calibration", f, d / "gt.yaml", *out]
    if command == "gate":
        if f.name == "gate.yaml":
            write(d / "result.json", RESULT)
            return ["gate", f, d / "result.json"]
        write(d / "gate.yaml", G)
        return ["gate", d / "gate.yaml", f]
    raise AssertionError(command)


def test_the_corpus_is_large_enough():
    assert len(CASES) >= 90 and len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("cid,command,name,content,fragment,code,extra", CASES, ids=[c[0] for c in CASES])
def test_malformed_output(tmp_path, cid, command, name, content, fragment, code, extra):
    f = tmp_path / name
    write(f, content)
    argv = argv_of(command, cid, f, tmp_path, extra)
    got, out, err = run_cli(main, argv)
    assert "Traceback" not in err and got == code, (got, err)
    if code == 2:
        assert len(err.strip().splitlines()) <= 4 and fragment in err, err  # argparse: usage + error
        assert str(f) in err or "--size" in err, err  # names the file (or the option)
    else:
        report = (tmp_path / "out.json").read_text() if (tmp_path / "out.json").is_file() else ""
        assert fragment in (out + report).lower()
