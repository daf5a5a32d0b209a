"""The stages after the views run as work items on Dask workers (issue 26): with an external
``dask scheduler`` and two workers, a moving stereo rig's sequence (cross-view pairs,
rectified stereo frames, board views; motion pairs, tracks, stereo motion pairs) gives the bytes
of a serial run, and the workers, not the driver, ran the stages' items."""
from __future__ import annotations

import sys
from pathlib import Path

import distributed
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset, verify
from scenegen.pipeline.distributed import worker_stats

sys.path.insert(0, str(Path(__file__).parent))
from external_dask import external_cluster, file_hashes  # noqa: E402

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
    with external_cluster(tmp_path, [(["--name", f"w{k}"], {}) for k in range(2)]) as (addr, _):
        out = tmp_path / "dist"
        assert main(["render", str(spec), "-o", str(out), "-q", "--scheduler", addr]) == 0
        with distributed.Client(addr, timeout="30s") as c:
            ran = {w: st["stage_items"] for w, st in c.run(worker_stats).items()}
    cv, seq = d.crossview.index, d.sequence.index
    n_items = (len(cv.pairs) + len(cv.stereo) + len(cv.targets)  # cross-view items
               + 2 * len(seq.pairs) + len(seq.streams) + len(seq.stereo_pairs))  # motion both ways, tracks, stereo
    assert sum(ran.values()) == n_items and len([n for n in ran.values() if n]) == 2, ran  # the workers ran them
    assert verify(out).ok
    assert file_hashes(out) == file_hashes(serial)
