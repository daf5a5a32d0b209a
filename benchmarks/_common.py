"""What the benchmarks share: interleaved A/B timing, summaries, the machine's load."""
from __future__ import annotations

import os
import resource
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # measure this checkout's code, whatever the venv's editable install points at
    sys.path.insert(0, str(ROOT))


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20


def load() -> str:
    """The 1-minute load average and the core count, for the record next to every figure."""
    try:
        one = os.getloadavg()[0]
    except OSError:
        return "load unknown"
    return f"load {one:.2f} on {os.cpu_count()} cores"


def interleaved(fns: dict, reps: int) -> dict[str, list]:
    """Run each function once per round, in turn (A B A B ...), ``reps`` rounds; each returns a
    number (seconds, or a ratio it measured itself). {name: [values]}."""
    out = {k: [] for k in fns}
    for _ in range(reps):
        for k, f in fns.items():
            out[k].append(f())
    return out


def timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def fmt(values, unit: str = "", scale: float = 1.0, digits: int = 2) -> str:
    """``median (min-max, n runs)``."""
    v = [x * scale for x in values]
    return (f"{statistics.median(v):.{digits}f}{unit} (min-max {min(v):.{digits}f}-{max(v):.{digits}f},"
            f" {len(v)} runs)")


def ratios(num, den) -> list[float]:
    """Per-round ratios of two interleaved series."""
    return [a / b for a, b in zip(num, den)]


def target(name: str, values, limit: float, *, at_most: bool = True) -> str:
    """One line a reader can grep: ``TARGET <name>: <median> (min-max) <= limit: met/NOT met``."""
    m = statistics.median(values)
    ok = m <= limit if at_most else m >= limit
    return (f"TARGET {name}: {fmt(values)} {'<=' if at_most else '>='} {limit}: "
            f"{'met' if ok else 'NOT met'} [{load()}]")
