"""The cluster path at scale (issue 32), not a test: N tiny views rendered through an external
``dask scheduler`` with 2 ``dask worker`` processes, as a user starts them. Sampled every 0.1 s
while it runs: the scheduler's tasks, those not yet finished (in flight), and this process's
(the client's) RSS. Optionally (``--serial``) the same spec serially, to compare the manifests.

Run: .venv/bin/python benchmarks/bench_dask_window.py [--views 2000] [--serial]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, load, rss_mb, target  # noqa: E402

SPEC = """
name: window
render: {{spp: 1, max_depth: 2}}
objects:
  - name: floor
    shape: {{type: plane, size: [3, 3]}}
  - name: ball
    shape: {{type: sphere, radius: 0.3}}
    transform: {{translation: [0, 0, 0.3]}}
lights:
  - {{type: point, position: [1, -1, 2], intensity: 5}}
cameras:
  cam: {{model: pinhole, size: [16, 12], fx: 14}}
views:
  - camera: cam
    orbit: {{center: [0, 0, 0.2], radius_m: 2.0, elevations_deg: [35], count: {n}}}
crossview: {{pairs: none}}
"""


def _dask_cli(sub: str) -> list[str]:
    cli = Path(sys.executable).with_name("dask")
    return [str(cli), sub] if cli.is_file() else [sys.executable, "-m", f"distributed.cli.dask_{sub}"]


def _scheduler_counts(dask_scheduler=None):
    tasks = dask_scheduler.tasks
    return len(tasks), sum(ts.state not in ("memory", "released", "forgotten", "erred") for ts in tasks.values())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--views", type=int, default=2000)
    ap.add_argument("--serial", action="store_true", help="also render serially and compare the manifests")
    args = ap.parse_args(argv)

    import distributed

    from scenegen.pipeline.run import render_spec

    tmp = Path(tempfile.mkdtemp(prefix="bench_dask_window_"))
    spec = tmp / "window.yaml"
    spec.write_text(SPEC.format(n=args.views))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp, env=env)
    sched_file = tmp / "scheduler.json"
    procs = [subprocess.Popen([*_dask_cli("scheduler"), "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(sched_file)], **quiet)]
    try:
        while not sched_file.is_file():
            time.sleep(0.05)
        addr = json.loads(sched_file.read_text())["address"]
        for _ in range(2):
            procs.append(subprocess.Popen([*_dask_cli("worker"), addr, "--nthreads", "1", "--no-nanny",
                                           "--no-dashboard"], **quiet))
        samples, stop = [], threading.Event()
        with distributed.Client(addr, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
            monitor = distributed.Client(addr, timeout="30s")  # its own connection: sampling never waits on the run

            def sample():
                while not stop.wait(0.1):
                    total, live = monitor.run_on_scheduler(_scheduler_counts)
                    samples.append((time.monotonic(), total, live, rss_mb()))

            t = threading.Thread(target=sample, daemon=True)
            rss0 = rss_mb()
            t0 = time.monotonic()
            t.start()
            summary = render_spec(spec, tmp / "dist", progress=False, dask_client=client)
            wall = time.monotonic() - t0
            stop.set()
            t.join()
            monitor.close()
    finally:
        for p in procs[::-1]:
            p.kill()
            p.wait(timeout=30)
    n = summary.views_rendered
    rss = [s[3] for s in samples]
    k = max(1, len(rss) // 10)
    print(f"{n} views of 16x12 px, 1 spp, on an external scheduler with 2 workers: {wall:.1f} s "
          f"({1000 * wall / n:.1f} ms per view); {load()}")
    print(f"scheduler tasks at most {max(s[1] for s in samples)}, not finished at most {max(s[2] for s in samples)} "
          f"({len(samples)} samples every 0.1 s)")
    tenths = [sum(rss[i * k:(i + 1) * k]) / len(rss[i * k:(i + 1) * k]) for i in range(len(rss) // k)]
    print(f"client RSS: {rss0:.0f} MB before; by tenth of the run (MB): {' '.join(f'{r:.0f}' for r in tenths)}; "
          f"max {max(rss):.0f} MB")
    print("  " + target("scheduler tasks not finished, at most (a few hundred)", [max(s[2] for s in samples)], 300))
    print("  " + target("client RSS last tenth / second tenth", [tenths[-1] / tenths[1]], 1.05))
    if args.serial:
        t0 = time.monotonic()
        render_spec(spec, tmp / "serial", progress=False)
        same = (tmp / "dist" / "manifest.json").read_bytes() == (tmp / "serial" / "manifest.json").read_bytes()
        print(f"serial: {time.monotonic() - t0:.1f} s; manifests byte-identical: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
