"""Run every benchmark (`make bench`): each prints ratios measured in the same run.

Figures are recorded in docs/performance.md (render, truth, scale) and docs/metrics.md (F-score).
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

if __name__ == "__main__":
    failed = 0
    for script in ("bench_render.py", "bench_fscore.py", "bench_scale.py"):
        print(f"== {script}", flush=True)
        failed |= subprocess.call([sys.executable, str(HERE / script)])
    # Cycles comparison: only where its optional bpy environment exists (bench_cycles.py --setup)
    if (HERE / ".venv-bpy" / "bin" / "python").is_file():
        print("== bench_cycles.py", flush=True)
        failed |= subprocess.call([sys.executable, str(HERE / "bench_cycles.py")])
    else:
        print("== bench_cycles.py: skipped (no benchmarks/.venv-bpy; run bench_cycles.py --setup)")
    sys.exit(failed)
