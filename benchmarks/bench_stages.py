"""The cross-view stage as work items (scenegen.pipeline.stages): 10 views of a static orbit at
320x240 give 18 items (9 view pairs and 9 flow pairs, both ways each), run serially in this
process and on a local Dask cluster of 2 workers (one task thread each, a Dr.Jit pool of
cores / workers threads; their scenes loaded by an untimed first run, as in a long run), 3
interleaved rounds. Prints the CPU of this process (the driver, with the cluster's scheduler) and
of the workers per item on Dask: the driver's bounds how many workers one driver keeps busy (a
worker's CPU per item / the driver's), and the wall time of 2 workers as a ratio of serial, as a
``TARGET`` line: >= 0.95 x serial's speed (Dr.Jit already uses both cores in one process, so no
gain is expected on 2 cores). On a loaded machine the wall ratio follows the CPU ratio (this
session's processes get their share of the cores), so the CPU of both ways is printed too.
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
                workers0 = client.run(time.process_time) if client is not None else {}
                cpu, t = time.process_time(), time.perf_counter()
                run_stage("crossview", spec, views, built, w, spp=4, seed=m["seed"], variant=m["variant"],
                          client=client, source=source)
                wall, cpu = time.perf_counter() - t, time.process_time() - cpu
                workers1 = client.run(time.process_time) if client is not None else {}
                return wall, cpu, sum(workers1[k] - workers0[k] for k in workers0)
            finally:
                w.close()

        n_items = len(STAGES["crossview"].plan(spec, views, lambda v: True, built).items)
        serial, serial_cpu, dask_wall, dask_cpu, workers_cpu = [], [], [], [], []
        with open_client(workers=2) as client:
            stage(client)  # the workers load the scene once, as in a long run
            for _ in range(3):  # interleaved: serial, then 2 workers
                wall, cpu, _ = stage(None)
                serial.append(wall)
                serial_cpu.append(cpu)
                wall, cpu, wcpu = stage(client)
                dask_wall.append(wall)
                dask_cpu.append(cpu)
                workers_cpu.append(wcpu)
    per_item_ms = [1000 * c / n_items for c in dask_cpu]
    worker_item_ms = [1000 * c / n_items for c in workers_cpu]  # an item's cost where it runs
    print(f"  {n_items} items; serial {fmt(serial, ' s')}; 2 workers {fmt(dask_wall, ' s')}")
    print(f"  CPU: serial {fmt(serial_cpu, ' s')}; on Dask the driver {fmt(dask_cpu, ' s')}, the workers"
          f" {fmt(workers_cpu, ' s')}; (driver + workers) / serial"
          f" {fmt([(d + w) / s for d, w, s in zip(dask_cpu, workers_cpu, serial_cpu)])}")
    print(f"  per item on Dask: the driver's CPU {fmt(per_item_ms, ' ms')}; a worker's CPU {fmt(worker_item_ms, ' ms')}")
    keep_busy = statistics.median(worker_item_ms) / statistics.median(per_item_ms)
    print(f"  one driver keeps about {keep_busy:.0f} workers busy (a worker's CPU per item / the driver's)")
    print("  " + target("2 workers / serial, speed (serial wall / 2-worker wall)",
                        [s / w for s, w in zip(serial, dask_wall)], 0.95, at_most=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
