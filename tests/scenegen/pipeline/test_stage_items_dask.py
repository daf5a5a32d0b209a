"""The stages after the views run as work items on Dask workers (issue 26): with an external
``dask scheduler`` and two workers, a moving stereo rig's sequence (cross-view pairs,
rectified stereo frames, board views; motion pairs, tracks, stereo motion pairs) gives the bytes
of a serial run, and the workers, not the driver, ran the stages' items."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import distributed
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset, verify
from scenegen.dataset.files import sha256_file
from scenegen.pipeline.distributed import worker_stats

ROOT = Path(__file__).resolve().parents[3]
_CLI = Path(sys.executable).with_name("dask")
DASK = (([str(_CLI), "scheduler"], [str(_CLI), "worker"]) if _CLI.is_file() else
        ([sys.executable, "-m", "distributed.cli.dask_scheduler"], [sys.executable, "-m", "distributed.cli.dask_worker"]))

SPEC = """
name: stage_items
render: {spp: 2, max_depth: 2}
sequence: {fps: 10, frames: 3, flow_steps: [1], tracks: {count: 24, query_frames: [0]}}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: noise, params: {size_px: 16}}}
  - name: board
    target: {type: checkerboard, inner_cols: 4, inner_rows: 3, square_m: 0.08}
    transform: {translation: [0, 0.1, 0.001]}
  - name: ball
    shape: {type: sphere, radius: 0.2}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [-0.3, -0.2, 0.2]}
        - {time_s: 0.2, translation: [0.3, -0.1, 0.3]}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [32, 24], fx: 28}
rigs:
  st: {type: stereo, left: cam, right: cam, baseline_m: 0.1}
views:
  - rig: st
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0.3, -1.6, 1.2], target: [0, 0, 0.1]}
        - {time_s: 0.2, eye: [-0.3, -1.5, 1.3], target: [0, 0, 0.1]}
crossview: {pairs: [[st_left_0000, st_right_0000], [st_left_0001, st_right_0001], [st_left_0002, st_right_0002]], flow: false, stereo: true}
"""


def _hashes(root: Path) -> dict:
    return {p.relative_to(root).as_posix(): sha256_file(p) for p in sorted(root.rglob("*")) if p.is_file()}


def _wait(cond, what: str, timeout_s: float = 60.0):
    t0 = time.monotonic()
    while not cond():
        if time.monotonic() - t0 > timeout_s:
            raise TimeoutError(what)
        time.sleep(0.05)


@pytest.mark.render
def test_stage_items_on_an_external_scheduler_give_the_serial_bytes(tmp_path):
    spec = tmp_path / "scene.yaml"
    spec.write_text(SPEC)
    serial = tmp_path / "serial"
    assert main(["render", str(spec), "-o", str(serial), "-q"]) == 0
    d = Dataset(serial)
    idx = d.crossview.index
    assert idx is not None and d.sequence.index is not None
    assert len(d.sequence.index.pairs) == 4 and d.sequence.index.stereo_pairs  # both stages have items
    sched_file = tmp_path / "scheduler.json"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp_path)
    procs = [subprocess.Popen([*DASK[0], "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(sched_file)], env=env, **quiet)]
    try:
        _wait(sched_file.is_file, "the scheduler did not start")
        addr = json.loads(sched_file.read_text())["address"]
        for k in range(2):
            procs.append(subprocess.Popen([*DASK[1], addr, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                                           "--name", f"w{k}"], env=env, **quiet))
        with distributed.Client(addr, timeout="30s") as c:
            c.wait_for_workers(2, timeout=60)
        out = tmp_path / "dist"
        assert main(["render", str(spec), "-o", str(out), "-q", "--scheduler", addr]) == 0
        with distributed.Client(addr, timeout="30s") as c:
            ran = {w: st["stage_items"] for w, st in c.run(worker_stats).items()}
    finally:
        for p in procs[::-1]:
            p.kill()
            p.wait(timeout=30)
    cv, seq = d.crossview.index, d.sequence.index
    n_items = (len(cv.pairs) + len(cv.stereo) + len(cv.targets)  # cross-view items
               + 2 * len(seq.pairs) + len(seq.streams) + len(seq.stereo_pairs))  # motion both ways, tracks, stereo
    assert sum(ran.values()) == n_items and len([n for n in ran.values() if n]) == 2, ran  # the workers ran them
    assert verify(out).ok
    assert _hashes(out) == _hashes(serial)
