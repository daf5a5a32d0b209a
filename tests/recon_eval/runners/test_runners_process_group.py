"""An estimator's children end with its invocation (recon_eval.runners.process_group, issue 25):
on a timeout, on an interrupt, and when the command exits leaving a child behind. The estimator
scripts start a sleeping child and record both pids; afterwards no process of the group runs."""
from __future__ import annotations

import json
import shlex
import sys
import time
from pathlib import Path

import pytest

from recon_eval.cli import main
from recon_eval.runners import external, process_group
from recon_eval.runners.common import RunOutput

SPAWN = """import os, subprocess, sys, time
child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
open(sys.argv[1], "w").write(f"{os.getpid()} {child.pid}")
print("started", file=sys.stderr, flush=True)
"""


def alive(pid: int) -> bool:
    """True while ``pid`` runs (a zombie, dead but not yet reaped by its new parent, does not count)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] not in ("Z", "X")


def wait_gone(pids, within_s=5.0) -> list[int]:
    """The pids still running after ``within_s`` (an orphan's reaping by init takes a moment)."""
    t0 = time.monotonic()
    while any(alive(p) for p in pids) and time.monotonic() - t0 < within_s:
        time.sleep(0.02)
    return [p for p in pids if alive(p)]


def script(tmp_path, tail: str) -> list[str]:
    f = tmp_path / "estimator.py"
    f.write_text(SPAWN + tail)
    return [sys.executable, str(f), str(tmp_path / "pids.txt")]


def pids(tmp_path) -> list[int]:
    return [int(p) for p in (tmp_path / "pids.txt").read_text().split()]


def test_a_hanging_estimator_and_its_child_are_killed_at_the_timeout(tmp_path):
    argv = script(tmp_path, "time.sleep(120)\n")
    command = " ".join(["{python}", *map(shlex.quote, argv[1:]), "{out}"])
    out = RunOutput()
    t0 = time.monotonic()
    why = external.invoke({"name": "hang", "command": command, "kind": "fmatrix", "timeout_s": 1.5}, {"out": "x"},
                          tmp_path / "log", "a__b", out)
    assert why == "timed out after 1.5 s" and time.monotonic() - t0 < 10
    assert len(pids(tmp_path)) == 2 and wait_gone(pids(tmp_path)) == []
    assert out.notes["a__b"]["stderr_tail"] == ["started"]


def test_a_child_left_behind_by_a_finished_estimator_ends_with_it(tmp_path):
    argv = script(tmp_path, "sys.exit(0)\n")  # the child keeps stdout and stderr open
    t0 = time.monotonic()
    status = process_group.run_group(argv, tmp_path / "o.txt", tmp_path / "e.txt", 60.0)
    assert status == 0 and time.monotonic() - t0 < 10  # not held until the timeout by the child's pipes
    assert wait_gone(pids(tmp_path)) == []


def test_an_interrupt_kills_the_group(tmp_path, monkeypatch):
    argv = script(tmp_path, "time.sleep(120)\n")
    real_sleep = time.sleep

    def interrupted(s):  # Ctrl-C arrives once the estimator has started its child
        if (tmp_path / "pids.txt").is_file() and (tmp_path / "pids.txt").read_text():
            raise KeyboardInterrupt
        real_sleep(s)

    monkeypatch.setattr(process_group.time, "sleep", interrupted)
    with pytest.raises(KeyboardInterrupt):
        process_group.run_group(argv, tmp_path / "o.txt", tmp_path / "e.txt", 60.0)
    monkeypatch.undo()
    assert len(pids(tmp_path)) == 2 and wait_gone(pids(tmp_path)) == []


def test_exit_statuses_and_a_missing_program(tmp_path):
    o, e = tmp_path / "o", tmp_path / "e"
    assert process_group.run_group([sys.executable, "-c", "raise SystemExit(3)"], o, e, 30) == 3
    assert process_group.run_group([sys.executable, "-c", "import os; os.kill(os.getpid(), 9)"], tmp_path / "o",
                                   tmp_path / "e", 30) == -9
    with pytest.raises(OSError):
        process_group.run_group([str(tmp_path / "no-such-program")], tmp_path / "o", tmp_path / "e", 30)


def test_run_command_with_a_hanging_estimator_ends_its_children(tmp_path):
    """The audit's case end to end: ``recon-eval run --command`` with an estimator that starts a
    child and hangs, ``--timeout 1``: the run completes, scored as a failure naming the method,
    and 0 processes of the group are left."""
    sys.path.insert(0, str(Path(__file__).parents[2] / "scenegen" / "dataset"))
    from test_dataset import write_dataset  # the hostile tests' small dataset

    write_dataset(tmp_path / "ds")
    argv = script(tmp_path, "time.sleep(120)\n")
    command = " ".join(["{python}", *map(shlex.quote, argv[1:]), "{images}", "{out}"])
    t0 = time.monotonic()
    code = main(["run", "--command", command, "--kind", "sfm", "--name", "hang", "--timeout", "1",
                 str(tmp_path / "ds"), "-o", str(tmp_path / "runs"), "--quiet"])
    assert code == 0 and time.monotonic() - t0 < 30
    notes = json.loads((tmp_path / "runs" / "result.json").read_text())["inputs"]["notes"]
    assert notes["sfm"]["failed"] == "timed out after 1 s"
    assert len(pids(tmp_path)) == 2 and wait_gone(pids(tmp_path)) == []
