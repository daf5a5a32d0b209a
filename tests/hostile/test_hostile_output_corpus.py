"""Every case of the malformed estimator-output corpus (tests/hostile/output_corpus.py) through
``recon_eval.cli.main``: the expected exit code and message fragment, one line, no traceback."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import run_cli, write_dataset, write_sequence_dataset  # noqa: E402
from output_corpus import (CAL, CASES, FLO_HEAD, GOOD_POSE, GOOD_TRACKS, H_GOOD, TUM_OK, G,  # noqa: E402
                           npy_bytes, tracks_npz)

from scenegen.dataset.codecs import encode_tracks  # noqa: E402

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


def argv_of(command, cid, f: Path, d: Path, extra) -> tuple[list, str]:
    """The command line of a case, its file in the estimate's (or truth's, gate's, estimator's)
    place, and what its error must name (the file, unless the case is about an option)."""
    if command == "tracks_truth":  # the case's file becomes the dataset's truth tracks
        truth = write_sequence_dataset(d / "seq", f.read_bytes())
        (d / "pred.npz").write_bytes(tracks_npz(GOOD_TRACKS.tracks_xy, GOOD_TRACKS.occluded))
        return ["tracks", d / "pred.npz", d / "seq", "--json", d / "out.json", "--quiet"], str(truth)
    if command == "run":
        write_dataset(d / "ds")
        places = {"FILE": str(f), "DS": str(d / "ds"), "RUNS": str(d / "runs")}
        return ["run", *(re.sub("FILE|DS|RUNS", lambda m: places[m.group()], x) for x in extra), "--quiet"], \
            str(f) if "--methods-file" in extra else ""  # else the option or method named in the fragment
    return _argv_of(command, cid, f, d, extra), str(f)


def _argv_of(command, cid, f: Path, d: Path, extra) -> list:
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
    if command == "tracks":
        write_sequence_dataset(d / "seq", encode_tracks(GOOD_TRACKS))
        return ["tracks", f, d / "seq", *out]
    if command == "flow":
        write(d / "gt.flo", FLO_HEAD + np.ones(24, "<f4").tobytes())
        return ["flow", f, d / "gt.flo", *out]
    raise AssertionError(command)


def test_the_corpus_is_large_enough():
    assert len(CASES) >= 90 and len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("cid,command,name,content,fragment,code,extra", CASES, ids=[c[0] for c in CASES])
def test_malformed_output(tmp_path, cid, command, name, content, fragment, code, extra):
    f = tmp_path / name
    write(f, content)
    argv, named = argv_of(command, cid, f, tmp_path, extra)
    got, out, err = run_cli(main, argv)
    assert "Traceback" not in err and got == code, (got, err)
    assert "None" not in err, err
    if code == 2:
        assert len(err.strip().splitlines()) <= 4 and fragment in err, err  # argparse: usage + error
        assert named in err or "--size" in err, err  # names the file (or the option: in the fragment)
    elif command == "run":  # a failed invocation is scored as a failure, and said so on stderr
        assert fragment in err, err
    else:
        report = (tmp_path / "out.json").read_text() if (tmp_path / "out.json").is_file() else ""
        assert fragment in (out + report).lower()


NATIVE = [c for c in CASES if c[0] in ("depth_exr_truncated", "depth_png_truncated", "flow_png_truncated")]


@pytest.mark.parametrize("cid,command,name,content,fragment,code,extra", NATIVE, ids=[c[0] for c in NATIVE])
def test_the_c_libraries_print_nothing_of_their_own(tmp_path, cid, command, name, content, fragment, code, extra):
    """OpenEXR and libpng (in OpenCV) write to descriptors 1 and 2 themselves, which the in-process
    run above cannot see: the whole output of a separate process is the one line."""
    f = tmp_path / name
    write(f, content)
    argv, named = argv_of(command, cid, f, tmp_path, extra)
    r = subprocess.run([sys.executable, "-m", "recon_eval", *map(str, argv)], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and r.stdout == "", (r.stdout, r.stderr)
    assert r.stderr.count("\n") == 1 and r.stderr.startswith(f"recon-eval: error: {named}: ") and fragment in r.stderr
