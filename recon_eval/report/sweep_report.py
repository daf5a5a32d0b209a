"""A sweep's report (``recon-eval sweep``; docs/fmatrix_survey.md, docs/sweeps.md): the figures of
error against noise and against outliers per method family, and the Markdown tables
(``--markdown``) of the mean and standard deviation of the kind's error (for F the
point-to-epipolar-line distance) per method and cell and of the breakdown points. What the error
is comes from the results' ``error`` (:func:`recon_eval.sweep.run.error_of`)."""
from __future__ import annotations

import math

from recon_eval.report import plots
from recon_eval.report.html import Figure

#: Errors above this (the kind's unit) are drawn at it in the plots.
PLOT_CEILING_PX = 1000.0
#: What a sweep document written before the sweep kinds reports (F alone, ``breakdown_px``).
F_ERROR = {"kind": "f", "label": "fundamental matrix", "measure": "distance of the truth points to the estimated "
           "epipolar lines, px", "unit": "px", "mean_key": "epi_mean_px", "std_key": "epi_std_px",
           "median_key": "median_trial_epi_px"}


def results_error(results: dict) -> dict:
    """What a sweep's cells report (its ``error``; F's for a document from before the kinds)."""
    return results.get("error", F_ERROR)


def _threshold(cfg: dict) -> float:
    return cfg["breakdown"] if "breakdown" in cfg else cfg["breakdown_px"]


def _px(v) -> str:
    v = float(v) if not isinstance(v, str) else float(v)  # JSON writes inf as "inf"
    if not math.isfinite(v):
        return "fail"
    return f"{v:.3g}"


def cell_entry(c, err) -> str:
    """``mean ± std`` of a cell's error (``err``: :func:`results_error`), or "fail"."""
    mean = _px(c[err["mean_key"]])
    return mean if mean == "fail" else f"{mean} ± {_px(c[err['std_key']])}"


def cells_table(results: dict, *, outlier_fraction=None, sigma_px=None, key: str | None = None) -> str:
    """Rows: methods; columns: the swept sigmas at ``outlier_fraction`` (or the fractions at
    ``sigma_px``); each entry ``mean ± std`` of the kind's error (F: px of the distances to the
    epipolar lines), or the cell's ``key`` (e.g. ``pose_err_deg``) when given."""
    cells, err = results["cells"], results_error(results)
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
            "" if c is None else (cell_entry(c, err) if key is None else _px(c[key])) for c in vals) + " |")
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
    cfg, err = results["config"], results_error(results)
    parts = [f"Breakdown: the smallest outlier fraction whose median trial error exceeds {_threshold(cfg)} "
             f"{err['unit']}.", "", breakdown_table(results), ""]
    what = ("the truth points' distances to the epipolar lines" if err["kind"] == "f"
            else f"the per-trial {err['measure'].split(',')[0]}")
    for f in cfg["outlier_fractions"]:
        parts += [f"Mean ± std ({err['unit']}) of {what}, {f:.0%} outliers:", "",
                  cells_table(results, outlier_fraction=f), ""]
    if err["kind"] == "f":
        for f in cfg["outlier_fractions"]:
            parts += [f"Median over the trials of the pose error through the truth K (deg), {f:.0%} outliers:", "",
                      cells_table(results, outlier_fraction=f, key="pose_err_deg"), ""]
    return "\n".join(parts)


def figures(results: dict) -> list[Figure]:
    """Error against noise (no outliers), and against the outlier fraction at each sigma, one panel per
    method family."""
    cells, cfg, err = results["cells"], results["config"], results_error(results)
    fam = {c["method"]: c["family"] for c in cells}
    unit = err["unit"]
    what = "distance to epipolar line" if err["kind"] == "f" else err["measure"].split(",")[0].split(":")[0]

    def panels(fixed_key, fixed, axis, value_key):
        out: dict = {}
        for m, f in fam.items():
            row = {c[axis]: float(c[value_key]) for c in cells if c["method"] == m and c[fixed_key] == fixed}
            out.setdefault(f, {})[m.removeprefix("survey-f-")] = [row[v] for v in sorted(row)]
        return out

    sig, fr = sorted(cfg["sigmas_px"]), sorted(cfg["outlier_fractions"])
    figs = [Figure("Error against noise", plots.panels_figure(
        sig, panels("outlier_fraction", fr[0], "sigma_px", err["mean_key"]), xlabel="sigma (px)",
        ylabel=f"mean {what} ({unit})", title=f"{fr[0]:.0%} outliers", ceiling=PLOT_CEILING_PX),
        f"mean over the trials of the {err['measure']}; open markers: failed or above {PLOT_CEILING_PX:g} {unit}")]
    for s in sig:
        figs.append(Figure(f"Error against outliers, sigma {s:g} px", plots.panels_figure(
            fr, panels("sigma_px", s, "outlier_fraction", err["median_key"]), xlabel="outlier fraction",
            ylabel=f"median trial error ({unit})", title=f"sigma {s:g} px", ceiling=PLOT_CEILING_PX,
            hline=_threshold(cfg)), f"dashed: the breakdown threshold {_threshold(cfg):g} {unit}"))
    return figs
