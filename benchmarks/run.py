"""Run every benchmark (`make bench`): each prints ratios measured in the same run, and the speed
targets of docs/performance.md as ``TARGET`` lines, collected again at the end.

Figures are recorded in docs/performance.md (render, truth, frames, start-up, scale, Cycles) and
docs/metrics.md (F-score, mesh distance).
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
BENCHES = ("bench_render.py", "bench_frame.py", "bench_warm.py", "bench_startup.py", "bench_codecs.py", "bench_fscore.py",
           "bench_mesh_distance.py", "bench_scale.py", "bench_flow.py", "bench_stages.py",
           "bench_structured_light.py")


def run(script: str, targets: list[str]) -> int:
    print(f"== {script}", flush=True)
    env = {**os.environ, "PYTHONPATH": str(HERE.parent)}  # this checkout's code
    p = subprocess.Popen([sys.executable, str(HERE / script)], stdout=subprocess.PIPE, text=True, env=env)
    for line in p.stdout:
        print(line, end="", flush=True)
        if "TARGET " in line:
            targets.append(f"{script}: {line.strip()}")
    return p.wait()


if __name__ == "__main__":
    failed, targets = 0, []
    for script in BENCHES:
        failed |= run(script, targets)
    # Cycles comparison: only where its optional bpy environment exists (bench_cycles.py --setup)
    if (HERE / ".venv-bpy" / "bin" / "python").is_file():
        failed |= run("bench_cycles.py", targets)
    else:
        print("== bench_cycles.py: skipped (no benchmarks/.venv-bpy; run bench_cycles.py --setup)")
    print("== targets (docs/performance.md)")
    print("\n".join(targets))
    sys.exit(failed)
