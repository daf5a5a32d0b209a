"""Warm processes (not a test): frame 0 of a new process against its steady frames, the scene
already compiled once by an earlier process (Dr.Jit's on-disk kernel cache; scenegen/render/arrays.py).

Each process loads the demo, then renders, casts the truth, encodes and writes ``--frames``
views one after the other (serially: frame 0 has nothing to overlap with) and reports each
frame's time and how many kernels it had to compile. The first process may compile (a cold
cache); the others must not.

Run: .venv/bin/python benchmarks/bench_warm.py [--processes 4] [--frames 6] [--spp 4]
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, load, target  # noqa: E402

CHILD = r"""
import json, sys, tempfile, time
t_start = time.perf_counter()
from pathlib import Path
from scenegen.render import load_scene
from scenegen.spec import load_spec, resolve_views
from scenegen.pipeline.view import render_view_data
from scenegen.dataset import DatasetWriter
import drjit as dr
spec = load_spec(sys.argv[1]); spp = int(sys.argv[2]); n = int(sys.argv[3])
views = resolve_views(spec)
t = time.perf_counter()
built = load_scene(spec, spp=spp)
t_load = time.perf_counter() - t
dr.set_flag(dr.JitFlag.KernelHistory, True)
w = DatasetWriter(Path(tempfile.mkdtemp()) / "out", spec_sha256="0" * 64, seed=0, variant=built.variant, versions={})
frames, compiled = [], []
for i in range(n):
    v = views[i % len(views)]
    dr.kernel_history_clear()
    t = time.perf_counter()
    image, linear, truth, extra = render_view_data(spec, built, i, v, spp=spp, seed=spec.render.seed)
    w.write_view(f"{v.name}_{i}", image=image, linear_rgb=linear, truth=truth, extra_files=extra)
    frames.append(time.perf_counter() - t)
    compiled.append(sum(1 for k in dr.kernel_history() if str(k.get("type")) == "KernelType.JIT" and not k.get("cache_hit")))
print("RESULT " + json.dumps({"frames": frames, "compiled": compiled, "load": t_load, "start": t_start}))
"""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--processes", type=int, default=4)
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--spec", default=str(ROOT / "scenes/demo.yaml"))
    args = ap.parse_args(argv)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    runs = []
    for _ in range(args.processes):
        out = subprocess.run([sys.executable, "-c", CHILD, args.spec, str(args.spp), str(args.frames)], check=True,
                             capture_output=True, text=True, env=env, cwd=ROOT).stdout
        runs.append(json.loads(out.split("RESULT ", 1)[1]))
    print(f"{Path(args.spec).name}, {args.spp} spp, {args.frames} frames per process, {load()}:")
    for i, r in enumerate(runs):
        print(f"  process {i}: scene load {r['load']:.2f} s; frames " + " ".join(f"{1e3 * x:.0f}" for x in r["frames"])
              + f" ms; kernels compiled per frame {r['compiled']}")
    warm = runs[1:]
    ratio = [r["frames"][0] / statistics.median(r["frames"][1:]) for r in warm]
    print(f"  frame 0 of processes 1-{len(runs) - 1}: {fmt([r['frames'][0] for r in warm], ' ms', 1e3, 0)};"
          f" kernels compiled in them: {sum(sum(r['compiled']) for r in warm)}")
    print("  " + target("second process: frame 0 / steady frame", ratio, 1.2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
