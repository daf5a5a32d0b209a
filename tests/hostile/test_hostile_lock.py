"""One writer per dataset folder (scenegen/dataset/lock.py): a second writer, in this process or
another, fails naming the owner; a lock left by a killed process is stale and taken over; the
fallback without flock (exclusive create) tells a dead pid on this host from a live one."""
from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import run_cli, write_dataset  # noqa: E402

sys.path.insert(0, str(Path(__file__).parents[1] / "scenegen" / "dataset"))
from test_dataset import all_bytes, new_writer  # noqa: E402

from scenegen.dataset import lock as lock_module  # noqa: E402
from scenegen.dataset.lock import LOCK_NAME, DatasetLock, DatasetLockedError  # noqa: E402

ROOT = Path(__file__).parents[2]
HOLDER = """
import sys
sys.path.insert(0, {tests!r})
from test_dataset import new_writer, write_dataset
w = new_writer({out!r}, resume=True)
print("locked", flush=True)
sys.stdin.readline()          # hold the lock until told to go on (or killed)
write_dataset({out!r}, writer=w)
print("done", flush=True)
"""


def holder(out: Path) -> subprocess.Popen:
    """Another process that resumes ``out`` and holds its lock until its stdin gets a line."""
    code = HOLDER.format(tests=str(ROOT / "tests" / "scenegen" / "dataset"), out=str(out))
    p = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         text=True, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert p.stdout.readline().strip() == "locked"
    return p


@pytest.fixture(scope="module")
def complete(tmp_path_factory):
    out = tmp_path_factory.mktemp("lock_complete") / "out"
    write_dataset(out)
    return out


def test_second_writer_in_this_process_is_refused_naming_the_owner(tmp_path):
    w = new_writer(tmp_path / "o")
    with pytest.raises(DatasetLockedError, match=rf"pid {os.getpid()} on host {socket.gethostname()}"):
        new_writer(tmp_path / "o", resume=True)
    w.close()
    assert not (tmp_path / "o" / LOCK_NAME).exists()  # a finished run leaves no lock
    new_writer(tmp_path / "o", resume=True).close()  # free again


def test_two_concurrent_resumes_one_waits_out_the_other_and_the_bytes_are_those_of_one_run(tmp_path, complete):
    out = tmp_path / "o"
    w = new_writer(out)
    w.abort()  # an interrupted run: a manifest, no views
    first = holder(out)
    try:
        with pytest.raises(DatasetLockedError, match=rf"pid {first.pid} on host"):
            new_writer(out, resume=True)
        # the second process, through the real CLI path of errors: one line, exit 2
        second = subprocess.run([sys.executable, "-c", HOLDER.format(
            tests=str(ROOT / "tests" / "scenegen" / "dataset"), out=str(out))], capture_output=True, text=True,
            cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}, stdin=subprocess.DEVNULL, timeout=120)
        assert second.returncode != 0 and "DatasetLockedError" in second.stderr
        assert f"pid {first.pid}" in second.stderr
        first.stdin.write("go\n")
        first.stdin.flush()
        assert first.stdout.readline().strip() == "done"
    finally:
        first.stdin.close()
        first.wait(timeout=120)
    assert first.returncode == 0
    assert all_bytes(out) == all_bytes(complete)


def test_a_killed_writers_lock_is_stale_and_taken_over(tmp_path, complete):
    out = tmp_path / "o"
    w = new_writer(out)
    w.abort()
    p = holder(out)
    p.send_signal(signal.SIGKILL)
    p.wait(timeout=60)
    assert (out / LOCK_NAME).is_file()  # the dead owner's file is still there
    w = new_writer(out, resume=True)
    assert w._lock.taken_over["pid"] == p.pid  # noqa: SLF001 - the record of whose lock it was
    write_dataset(out, writer=w)
    assert all_bytes(out) == all_bytes(complete)  # and the lock is gone


TINY = """
name: tiny
render: {spp: 4, max_depth: 2}
objects:
  - {name: ball, shape: {type: sphere, radius: 0.3}, material: {type: diffuse, color: 0.5}}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam: {model: pinhole, size: [64, 48], fx: 60, fy: 60, cx: 32, cy: 24}
views:
  - camera: cam
    orbit: {center: [0, 0, 0], radius_m: 2.0, elevations_deg: [30], count: 2}
"""


@pytest.mark.render
def test_the_cli_refuses_a_second_writer_with_one_line_and_exit_2(tmp_path):
    from scenegen.cli import main
    spec = tmp_path / "tiny.yaml"
    spec.write_text(TINY)
    out = tmp_path / "o"
    w = new_writer(out)
    try:
        code, _, err = run_cli(main, ["render", spec, "-o", out, "--resume", "-q"])
    finally:
        w.abort()
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert f"is being written by another scenegen run (pid {os.getpid()} on host" in err
    assert main(["render", str(spec), "-o", str(tmp_path / "p"), "-q"]) == 0  # a free folder renders


@pytest.fixture()
def no_flock(monkeypatch):
    monkeypatch.setattr(lock_module, "fcntl", None)


def write_lock_file(root: Path, pid: int, host: str) -> None:
    root.mkdir(parents=True, exist_ok=True)
    (root / LOCK_NAME).write_text(json.dumps({"pid": pid, "host": host, "since": "then"}))


def dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_fallback_takes_over_a_dead_pid_on_this_host(tmp_path, no_flock):
    pid = dead_pid()
    write_lock_file(tmp_path, pid, socket.gethostname())
    lock = DatasetLock.acquire(tmp_path)
    assert lock.taken_over["pid"] == pid
    assert json.loads((tmp_path / LOCK_NAME).read_text())["pid"] == os.getpid()
    lock.release()
    assert not (tmp_path / LOCK_NAME).exists()


@pytest.mark.parametrize("host", ["this", "elsewhere"])
def test_fallback_refuses_a_live_pid_and_any_other_hosts_lock(tmp_path, no_flock, host):
    pid = os.getpid() if host == "this" else dead_pid()
    write_lock_file(tmp_path, pid, socket.gethostname() if host == "this" else "another-host.example")
    with pytest.raises(DatasetLockedError, match=rf"pid {pid} on host .*if that run is gone, delete"):
        DatasetLock.acquire(tmp_path)
    assert (tmp_path / LOCK_NAME).is_file()  # never broken


def test_an_unreadable_lock_file_is_reported_not_broken(tmp_path, no_flock):
    (tmp_path / LOCK_NAME).write_bytes(b"\x00garbage")
    with pytest.raises(DatasetLockedError, match="an unknown process"):
        DatasetLock.acquire(tmp_path)


KILLED = TINY.replace("count: 2}", "count: 24}")
# The render under test pauses after each journal record of its views (a tiny view takes
# milliseconds: 24 of them, on 2 Dask workers, could all be recorded and the run finished between
# two looks at the journal), so the kill lands while the run is alive with views recorded. A pause
# changes no byte.
PAUSE_AFTER_RECORDING = """
import sys, time
from scenegen.dataset.writer import DatasetWriter
for name in ("record_view", "record_views"):
    def paused(self, *a, _real=getattr(DatasetWriter, name), **kw):
        _real(self, *a, **kw)
        time.sleep(0.3)
    setattr(DatasetWriter, name, paused)
from scenegen.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.render
@pytest.mark.parametrize("workers", [None, 2])
def test_kill_9_mid_render_then_resume_takes_over_the_stale_lock_and_gives_the_bytes_of_one_run(tmp_path, workers):
    import time
    from scenegen.cli import main
    spec = tmp_path / "tiny.yaml"
    spec.write_text(KILLED)
    ref = tmp_path / "ref"
    assert main(["render", str(spec), "-o", str(ref), "-q"]) == 0
    out = tmp_path / "out"
    argv = [sys.executable, "-c", PAUSE_AFTER_RECORDING, "render", str(spec), "-o", str(out), "-q"]
    if workers:
        argv += ["--workers", str(workers)]
    p = subprocess.Popen(argv, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}, start_new_session=True,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    journal = out / "manifest.journal"
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and p.poll() is None:
        if journal.is_file() and b'"op":"view"' in journal.read_bytes():
            break
        time.sleep(0.05)
    assert p.poll() is None, "the run ended before it could be killed"
    os.killpg(p.pid, signal.SIGKILL)  # the client and its Dask workers
    p.wait(timeout=60)
    assert (out / LOCK_NAME).is_file()  # left by the killed run: stale
    assert main(["render", str(spec), "-o", str(out), "--resume", "-q"]) == 0
    assert all_bytes(out) == all_bytes(ref)


def test_discard_removes_only_a_folder_its_writer_created(tmp_path):
    made = tmp_path / "made"
    w = new_writer(made)
    assert w.discard() and not made.exists()  # created here, nothing completed: gone
    existing = tmp_path / "existing"
    existing.mkdir()
    w = new_writer(existing)
    assert not w.discard() and sorted(p.name for p in existing.iterdir()) == ["manifest.json"]
    assert not list(tmp_path.glob(".*"))  # no residue of the discarded folder
