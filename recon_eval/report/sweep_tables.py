"""Markdown tables of a sweep's results (``recon-eval sweep --markdown``; docs/fmatrix_survey.md):
the mean and standard deviation of the point-to-epipolar-line distance per method and cell, and
the breakdown points."""
from __future__ import annotations

import math


def _px(v) -> str:
    v = float(v) if not isinstance(v, str) else float(v)  # JSON writes inf as "inf"
    if not math.isfinite(v):
        return "fail"
    return f"{v:.3g}" if v < 1000 else f"{v:.0f}"


def cells_table(results: dict, *, outlier_fraction=None, sigma_px=None) -> str:
    """Rows: methods; columns: the swept sigmas at ``outlier_fraction`` (or the fractions at
    ``sigma_px``); each entry ``mean ± std`` px of the distances to the epipolar lines."""
    cells = results["cells"]
    if outlier_fraction is not None:
        cells = [c for c in cells if c["outlier_fraction"] == outlier_fraction]
        axis, head = "sigma_px", "sigma {} px"
    else:
        cells = [c for c in cells if c["sigma_px"] == sigma_px]
        axis, head = "outlier_fraction", "{:.0%} outliers"
    cols = sorted({c[axis] for c in cells})
    methods = list(dict.fromkeys(c["method"] for c in cells))
    by = {(c["method"], c[axis]): c for c in cells}
    lines = ["| method | family | " + " | ".join(head.format(v) for v in cols) + " |",
             "|---|---|" + "---:|" * len(cols)]
    for m in methods:
        fam = next(c["family"] for c in cells if c["method"] == m)
        vals = [by.get((m, v)) for v in cols]
        lines.append(f"| `{m}` | {fam} | " + " | ".join(
            "" if c is None else f"{_px(c['epi_mean_px'])} ± {_px(c['epi_std_px'])}" for c in vals) + " |")
    return "\n".join(lines)


def breakdown_table(results: dict) -> str:
    """Rows: methods; columns: the swept sigmas; each entry the breakdown outlier fraction, or
    "> f" when even the largest swept fraction f held."""
    rows = results["breakdown"]
    sigmas = sorted({r["sigma_px"] for r in rows})
    methods = list(dict.fromkeys(r["method"] for r in rows))
    by = {(r["method"], r["sigma_px"]): r for r in rows}
    lines = ["| method | family | " + " | ".join(f"sigma {s} px" for s in sigmas) + " |",
             "|---|---|" + "---:|" * len(sigmas)]
    for m in methods:
        fam = by[(m, sigmas[0])]["family"]
        ent = []
        for s in sigmas:
            r = by[(m, s)]
            b = r["breakdown_fraction"]
            ent.append(f"> {r['max_fraction_swept']:.0%}" if b is None else f"{b:.0%}")
        lines.append(f"| `{m}` | {fam} | " + " | ".join(ent) + " |")
    return "\n".join(lines)


def markdown(results: dict) -> str:
    """Every table of a sweep: per outlier fraction (error vs noise), per sigma (error vs outliers),
    and the breakdown points."""
    cfg = results["config"]
    parts = [f"Breakdown: the smallest outlier fraction whose median trial error exceeds {cfg['breakdown_px']} px.",
             "", breakdown_table(results), ""]
    for f in cfg["outlier_fractions"]:
        parts += [f"Mean ± std (px) of the truth points' distances to the epipolar lines, {f:.0%} outliers:", "",
                  cells_table(results, outlier_fraction=f), ""]
    return "\n".join(parts)
