"""The compact tables of docs/sweeps.md from sweeps' results (``recon-eval sweep --kind K ... -o OUT``):

    .venv/bin/python docs/figures/sweeps.py OUT_H/sweep.json OUT_E/sweep.json ...

per sweep, one row per method: mean ± std of the kind's error without noise, at sigma 1 px with 0,
20 and 40 % outliers, and the breakdown fraction at each sigma (as ``recon-eval sweep --markdown``
writes them in full).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from recon_eval.report.sweep_report import cell_entry, results_error


def table(results: dict) -> str:
    err, cfg = results_error(results), results["config"]
    cells = {(c["method"], c["sigma_px"], c["outlier_fraction"]): c for c in results["cells"]}
    bd = {(r["method"], r["sigma_px"]): r for r in results["breakdown"]}
    sig = "/".join(f"{s:g}" for s in cfg["sigmas_px"])
    cols = [(0.0, 0.0), *((1.0, f) for f in cfg["outlier_fractions"])]
    head = " | ".join(f"sigma {s:g} px, {f:.0%} outliers" for s, f in cols)
    lines = [f"| method | {head} | breakdown, sigma {sig} px |", "|---|" + "---:|" * (len(cols) + 1)]
    for m in dict.fromkeys(c["method"] for c in results["cells"]):
        b = [bd[(m, s)] for s in cfg["sigmas_px"]]
        brk = " / ".join(f"> {r['max_fraction_swept']:.0%}" if r["breakdown_fraction"] is None
                         else f"{r['breakdown_fraction']:.0%}" for r in b)
        lines.append(f"| `{m}` | " + " | ".join(cell_entry(cells[(m, s, f)], err) for s, f in cols) + f" | {brk} |")
    return f"{err['label']}: {err['measure']}\n\n" + "\n".join(lines)


if __name__ == "__main__":
    for path in sys.argv[1:]:
        print(table(json.loads(Path(path).read_text())["results"]) + "\n")
