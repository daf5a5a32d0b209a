"""One estimator invocation as a process group that ends with it.

The command starts in a new session (its own process group, ``start_new_session=True``), so the
children it starts are in the group too. When the command exits, times out, fails or is
interrupted (Ctrl-C, an exception in recon-eval), the whole group is killed with
``os.killpg``: no child of an estimator outlives its invocation. The leader is waited for
without being reaped (``waitid(WNOWAIT)``) until its group is killed, so the group id, which is
the leader's pid, cannot have been reused by then. A child that leaves the group (``setsid``)
escapes, as from any process manager short of a container.

stdout and stderr go straight to files, so a child that keeps them open cannot hold the
invocation past its command's exit.
"""
from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

#: Longest sleep between two looks at the running command, seconds (Popen.wait's own cap).
POLL_MAX_S = 0.05


def run_group(argv: list[str], stdout_path: Path, stderr_path: Path, timeout_s: float) -> int | None:
    """The exit status of ``argv`` run in its own process group with stdin closed and its output
    in the two files; None if it ran past ``timeout_s`` seconds. The group is killed whichever
    way the call ends. OSError if the program cannot start."""
    with open(stdout_path, "wb") as out, open(stderr_path, "wb") as err:
        p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=out, stderr=err, start_new_session=True)
    try:
        exited = _wait_unreaped(p.pid, time.monotonic() + timeout_s)
    finally:
        _kill_group(p.pid)  # the leader is not reaped yet: its pid is still the group's id
        p.wait()
    return p.returncode if exited else None


def _wait_unreaped(pid: int, deadline: float) -> bool:
    """True once the process ``pid`` (our child) has exited, left unreaped; False at ``deadline``."""
    pause = 0.0005
    while True:
        if os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None:
            return True
        left = deadline - time.monotonic()
        if left <= 0:
            return False
        pause = min(pause * 2, left, POLL_MAX_S)
        time.sleep(pause)


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except ProcessLookupError:  # the group is empty but for the unreaped leader on some systems
        pass
