"""The cross-view stage as work items (scenegen.pipeline.stages): 10 views of a static orbit at
320x240 give 20 items (10 view pairs and 10 flow pairs, both ways each), run serially in this
process and on a local Dask cluster of 2 workers (one thread each; their scenes loaded by an
untimed first run, as in a long run). Prints the driver's own CPU per item on Dask (it bounds
how many workers one driver keeps busy: a worker's item time / the driver's CPU per item) and
the wall time of 2 workers as a ratio of serial, as a ``TARGET`` line: >= 0.95 x serial's speed
(Dr.Jit already uses both cores in one process, so no gain is expected on 2 cores).
"""
from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

from _common import fmt, load, target

SPEC = """
name: bench_stages
render: {spp: 4, max_depth: 2}
objects:
  - name: floor
    shape: {type: plane, size: [4, 4]}
    material: {type: diffuse, texture: {type: noise, params: {size_px: 64}}}
  - {name: ball, shape: {type: sphere, radius: 0.3}, transform: {translation: [0, 0, 0.3]}}
  - {name: crate, shape: {type: box, size: [0.4, 0.3, 0.3]}, transform: {translation: [0.6, 0.2, 0.15]}}
lights: [{type: constant, radiance: 1}]
cameras: {cam: {size: [320, 240], fx: 280}}
views:
  - camera: cam
    orbit: {center: [0, 0, 0.2], radius_m: 2.5, elevations_deg: [30], count: 10}
crossview: {pairs: consecutive, flow: true}
"""


def main() -> int:
    from scenegen.dataset.writer import DatasetWriter
    from scenegen.pipeline.distributed import open_client
    from scenegen.pipeline.run import render_spec
    from scenegen.pipeline.stages import STAGES, run_stage
    from scenegen.render import load_scene
    from scenegen.spec import load_spec, resolve_views
    from scenegen.spec.source import SpecSource

    print(f"bench_stages ({load()})")
    with tempfile.TemporaryDirectory() as d:
        spec_path = Path(d) / "scene.yaml"
        spec_path.write_text(SPEC)
        out = Path(d) / "out"
        render_spec(spec_path, out, progress=False)
        m = __import__("json").loads((out / "manifest.json").read_text())
        spec = load_spec(spec_path)
        views = resolve_views(spec)
        built = load_scene(spec, spp=4)
        source = SpecSource.from_path(spec_path)

        def stage(client):
            w = DatasetWriter(out, spec_sha256=m["spec_sha256"], seed=m["seed"], variant=m["variant"],
                              versions=m["versions"], resume=True)
            try:
                cpu, t = time.process_time(), time.perf_counter()
                run_stage("crossview", spec, views, built, w, spp=4, seed=m["seed"], variant=m["variant"],
                          client=client, source=source)
                return time.perf_counter() - t, time.process_time() - cpu
            finally:
                w.close()

        n_items = len(STAGES["crossview"].plan(spec, views, lambda v: True, built).items)
        serial, dask_wall, dask_cpu = [], [], []
        with open_client(workers=2) as client:
            stage(client)  # the workers load the scene once, as in a long run
            for _ in range(3):  # interleaved: serial, then 2 workers
                serial.append(stage(None)[0])
                wall, cpu = stage(client)
                dask_wall.append(wall)
                dask_cpu.append(cpu)
    per_item_ms = [1000 * c / n_items for c in dask_cpu]
    worker_item_ms = [1000 * s / n_items for s in serial]  # an item's cost where it runs
    print(f"  {n_items} items; serial {fmt(serial, ' s')}; 2 workers {fmt(dask_wall, ' s')}")
    print(f"  driver CPU per item on Dask: {fmt(per_item_ms, ' ms')}; an item's own time: {fmt(worker_item_ms, ' ms')}")
    keep_busy = statistics.median(worker_item_ms) / statistics.median(per_item_ms)
    print(f"  one driver keeps about {keep_busy:.0f} workers busy (item time / driver CPU per item)")
    print("  " + target("2 workers / serial, speed (serial wall / 2-worker wall)",
                        [s / w for s, w in zip(serial, dask_wall)], 0.95, at_most=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
