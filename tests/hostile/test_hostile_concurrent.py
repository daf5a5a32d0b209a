"""Two renders into one folder at once (issue 25's data loss): the second writer is refused by the
folder lock, and a refused writer never deletes what it did not create. Whatever the start delay,
the live writer's dataset verifies and has the bytes of a run alone; concurrent ``--resume`` runs
end with a dataset that verifies, 10 rounds of 10.

Both processes render through a wrapper that sleeps before each view; in the refused-writer test the
wrapper also keeps the lock holder from closing the folder (which releases the lock) until the test
has seen the other process exit, so the second writer meets a held lock however slowly a loaded
machine starts it (without that wait, a holder that finished before the other process had even
imported was not refused at all: "not empty" instead). A sleep or a wait changes no byte."""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
SPEC = """
name: concurrent
render: {spp: 4, max_depth: 2}
objects:
  - {name: ball, shape: {type: sphere, radius: 0.3}, material: {type: diffuse, color: 0.5}}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam: {model: pinhole, size: [32, 24], fx: 30, fy: 30, cx: 16, cy: 12}
views:
  - camera: cam
    orbit: {center: [0, 0, 0], radius_m: 2.0, elevations_deg: [30], count: 4}
"""
SLOW = """
import os, sys, time
from scenegen.dataset.writer import DatasetWriter
from scenegen.pipeline import run
real = run.render_view_data
def slow(*a, **kw):
    time.sleep({sleep})
    return real(*a, **kw)
run.render_view_data = slow
gate = os.environ.get({gate_env!r})
if gate:  # the lock is released in close(): hold it until the test creates the gate file
    real_close = DatasetWriter.close
    def gated_close(self):
        t0 = time.monotonic()
        while not os.path.exists(gate) and time.monotonic() - t0 < {gate_timeout_s}:
            time.sleep(0.02)
        return real_close(self)
    DatasetWriter.close = gated_close
from scenegen.cli import main
sys.exit(main(sys.argv[1:]))
"""
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
GATE_ENV = "SCENEGEN_TEST_CLOSE_GATE"
GATE_TIMEOUT_S = 240  # a lock holder never waits longer (a broken test must not leave it hanging)


def start(args, sleep: float = 0.0, gate: Path | None = None) -> subprocess.Popen:
    """``scenegen`` with ``args``, sleeping ``sleep`` s before each view; with ``gate``, a writer
    that took the lock does not close its folder before the file ``gate`` exists."""
    code = SLOW.format(sleep=sleep, gate_env=GATE_ENV, gate_timeout_s=GATE_TIMEOUT_S)
    env = {**ENV, GATE_ENV: str(gate)} if gate is not None else ENV
    return subprocess.Popen([sys.executable, "-c", code, *map(str, args)], cwd=ROOT, env=env,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for_either(a: subprocess.Popen, b: subprocess.Popen, timeout_s: float = GATE_TIMEOUT_S) -> None:
    """Until one of the two processes has exited (or ``timeout_s``: the assertions then tell)."""
    t0 = time.monotonic()
    while a.poll() is None and b.poll() is None and time.monotonic() - t0 < timeout_s:
        time.sleep(0.05)


def finish(p: subprocess.Popen) -> tuple[int, str]:
    _, err = p.communicate(timeout=300)
    return p.returncode, err


def file_hashes(root: Path) -> dict[str, str]:
    return {p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def verifies(out: Path) -> bool:
    from scenegen.cli import main
    return main(["verify", str(out), "-q"]) == 0


@pytest.fixture(scope="module")
def spec_and_reference(tmp_path_factory):
    d = tmp_path_factory.mktemp("concurrent")
    spec = d / "spec.yaml"
    spec.write_text(SPEC)
    ref = d / "ref"
    code, err = finish(start(["render", spec, "-o", ref, "-q"]))
    assert code == 0, err
    return spec, file_hashes(ref)


def no_leftovers(parent: Path) -> bool:
    """No discarded-folder residue and no temporary files beside the datasets."""
    return not [p for p in parent.iterdir() if p.name.startswith(".")]


@pytest.mark.render
@pytest.mark.parametrize("delay_s", [0.1, 0.2, 0.4, 0.8])
def test_a_refused_second_writer_leaves_the_live_writers_dataset_whole(tmp_path, spec_and_reference, delay_s):
    spec, reference = spec_and_reference
    out, gate = tmp_path / "out", tmp_path / "gate"
    first = start(["render", spec, "-o", out, "-q"], sleep=0.5, gate=gate)
    time.sleep(delay_s)
    second = start(["render", spec, "-o", out, "-q"], sleep=0.5, gate=gate)
    wait_for_either(first, second)  # the refused one; the lock holder waits at close() meanwhile
    gate.touch()
    (code1, err1), (code2, err2) = finish(first), finish(second)
    # whichever reaches the lock first writes; the other is refused while it runs (the lock names
    # its owner): one line, no traceback
    assert sorted([code1, code2]) == [0, 2], (err1, err2)
    refused = err1 if code1 == 2 else err2
    assert "being written by another scenegen run" in refused and "Traceback" not in refused, refused
    assert file_hashes(out) == reference and verifies(out)
    assert no_leftovers(tmp_path)


@pytest.mark.render
def test_concurrent_resumes_always_end_with_a_dataset_that_verifies(tmp_path, spec_and_reference):
    spec, reference = spec_and_reference
    outcomes = []
    for round_ in range(10):
        out = tmp_path / f"out{round_}"
        first = start(["render", spec, "-o", out, "--resume", "-q"], sleep=0.3)
        time.sleep(0.1 * round_)
        second = start(["render", spec, "-o", out, "--resume", "-q"], sleep=0.3)
        (code1, err1), (code2, err2) = finish(first), finish(second)
        # one of them writes; the other is refused (exit 2, naming the owner) or finds it complete
        assert {code1, code2} <= {0, 2} and 0 in (code1, code2), (err1, err2)
        for code, err in ((code1, err1), (code2, err2)):
            assert code == 0 or "being written by another scenegen run" in err, err
        assert file_hashes(out) == reference and verifies(out), f"round {round_}"
        outcomes.append((code1, code2))
    assert no_leftovers(tmp_path)
    assert any(2 in o for o in outcomes)  # the race was exercised, not only runs one after the other
