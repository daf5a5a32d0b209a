"""Start-up of the command line (not a test): ``scenegen --help`` and ``scenegen validate`` in new
processes, against ``python -c "import numpy"`` and a script that imports numpy and parses the spec.

The spec parse is what ``validate`` cannot avoid: the import of scenegen.spec and what the spec
needs (yaml; scipy for a rotation; the camera's validity checks), ``load_spec``, ``resolve_views``
and ``to_camera``. The script doing only that, after ``import numpy``, is the budget of
``validate`` (its in-process part is printed too). Each command runs ``--reps`` times,
interleaved; ratios per round.

Run: .venv/bin/python benchmarks/bench_startup.py [--reps 7] [--spec scenes/demo.yaml]
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, interleaved, ratios, target  # noqa: E402

PARSE = """
import sys, time
import numpy
t = time.perf_counter()
from scenegen.spec import load_spec, resolve_views
spec = load_spec(sys.argv[1])
resolve_views(spec)
for c in spec.cameras.values():
    c.to_camera()
print(time.perf_counter() - t)
"""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--spec", default=str(ROOT / "scenes/demo.yaml"))
    args = ap.parse_args(argv)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}

    def run(*cmd) -> float:
        t = time.perf_counter()
        subprocess.run([sys.executable, *cmd], check=True, capture_output=True, env=env, cwd=ROOT)
        return time.perf_counter() - t

    def parse() -> float:
        out = subprocess.run([sys.executable, "-c", PARSE, args.spec], check=True, capture_output=True, text=True,
                             env=env, cwd=ROOT).stdout
        return float(out.split()[-1])

    r = interleaved({"numpy": lambda: run("-c", "import numpy"), "help": lambda: run("-m", "scenegen.cli", "--help"),
                     "validate": lambda: run("-m", "scenegen.cli", "validate", args.spec),
                     "script": lambda: run("-c", PARSE, args.spec), "parse": parse}, args.reps)
    print(f"new processes, {Path(args.spec).name}:")
    for k, label in (("numpy", "python -c 'import numpy'"), ("help", "scenegen --help"),
                     ("validate", "scenegen validate"), ("script", "python: import numpy + the spec parse"),
                     ("parse", "  of which the spec parse (in-process, after numpy)")):
        print(f"  {label}: {fmt(r[k], ' ms', 1e3, 0)}")
    print("  " + target("scenegen --help / import numpy", ratios(r["help"], r["numpy"]), 1.0))
    print("  " + target("scenegen validate / (import numpy + spec parse)", ratios(r["validate"], r["script"]), 1.0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
