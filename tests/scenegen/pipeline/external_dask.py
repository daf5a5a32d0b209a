"""An external Dask cluster as a user starts one (``dask scheduler``, ``dask worker``), for the
tests that render through ``scenegen render --scheduler``; and the file hashes they compare."""
from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import distributed

from scenegen.dataset.files import sha256_file

ROOT = Path(__file__).resolve().parents[3]
_CLI = Path(sys.executable).with_name("dask")
DASK = (([str(_CLI), "scheduler"], [str(_CLI), "worker"]) if _CLI.is_file() else
        ([sys.executable, "-m", "distributed.cli.dask_scheduler"], [sys.executable, "-m", "distributed.cli.dask_worker"]))
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}


def file_hashes(root: Path) -> dict:
    """{relative path: sha256} of every file under ``root``."""
    return {p.relative_to(root).as_posix(): sha256_file(p) for p in sorted(root.rglob("*")) if p.is_file()}


def wait_for(cond, what: str, timeout_s: float = 60.0) -> None:
    t0 = time.monotonic()
    while not cond():
        if time.monotonic() - t0 > timeout_s:
            raise TimeoutError(what)
        time.sleep(0.05)


@contextlib.contextmanager
def external_cluster(tmp_path: Path, workers):
    """A scheduler on 127.0.0.1 and one ``dask worker`` per entry of ``workers`` (each: (extra
    arguments, extra environment)), one thread each, no nanny; yields (address, worker processes).
    Every process is killed on exit."""
    sched_file = tmp_path / "scheduler.json"
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path)
    procs = [subprocess.Popen([*DASK[0], "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(sched_file)], env=ENV, **quiet)]
    try:
        wait_for(sched_file.is_file, "the scheduler did not start")
        addr = json.loads(sched_file.read_text())["address"]
        for args, env in workers:
            procs.append(subprocess.Popen([*DASK[1], addr, "--nthreads", "1", "--no-nanny", "--no-dashboard", *args],
                                          env={**ENV, **env}, **quiet))
        with distributed.Client(addr, timeout="30s") as c:
            c.wait_for_workers(len(workers), timeout=60)
        yield addr, procs[1:]
    finally:
        for p in procs[::-1]:
            p.kill()
            p.wait(timeout=30)
