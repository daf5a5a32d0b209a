"""A sweep's tables and figures (recon_eval.report.sweep_report) from a hand-made result."""
from __future__ import annotations

import math

from recon_eval.report.sweep_report import breakdown_table, cells_table, figures, markdown
from recon_eval.sweep.summary import breakdown_points


def _results():
    cells = []
    for m, fam, errs in (("survey-f-fns", "iterative", {0.0: (0.1, 30.0), 1.0: (0.4, 50.0)}),
                         ("survey-f-ransac", "robust", {0.0: (0.1, 0.2), 1.0: (0.3, 0.5)})):
        for s, (e0, e1) in errs.items():
            for f, e in ((0.0, e0), (0.4, e1)):
                cells.append({"method": m, "family": fam, "sigma_px": s, "outlier_fraction": f, "epi_mean_px": e,
                              "epi_std_px": e / 2, "median_trial_epi_px": e, "pose_err_deg": 10 * e})
    cells[-1]["epi_mean_px"] = math.inf  # a failed cell reads "fail"
    # a document from before the sweep kinds: F's keys, ``breakdown_px``
    cfg = {"sigmas_px": [0.0, 1.0], "outlier_fractions": [0.0, 0.4], "breakdown_px": 1.0}
    return {"config": cfg, "cells": cells, "breakdown": breakdown_points(cells, 1.0)}


def test_tables_state_mean_std_and_breakdown():
    r = _results()
    t = cells_table(r, outlier_fraction=0.0)
    assert "| `survey-f-fns` | iterative | 0.1 ± 0.05 | 0.4 ± 0.2 |" in t
    assert "| `survey-f-ransac` | robust | 0.3 ± 0.15 | fail |" in cells_table(r, sigma_px=1.0)
    b = breakdown_table(r)
    assert "| `survey-f-fns` | iterative | 40% | 40% |" in b and "| `survey-f-ransac` | robust | > 40% | > 40% |" in b
    assert "| `survey-f-fns` | iterative | 1 | 4 |" in cells_table(r, outlier_fraction=0.0, key="pose_err_deg")
    assert markdown(r).count("|---|---|") == 5


def test_figures_are_pngs_per_sigma():
    figs = figures(_results())
    assert [f.title for f in figs] == ["Error against noise", "Error against outliers, sigma 0 px",
                                       "Error against outliers, sigma 1 px"]
    assert all(f.png[:8] == b"\x89PNG\r\n\x1a\n" for f in figs)


def test_tables_and_figures_follow_the_kinds_error():
    """Another kind's results (the sweep's ``error``: its keys, unit and threshold) give its tables."""
    err = {"kind": "pnp", "label": "PnP", "measure": "reprojection RMS, px", "unit": "px", "mean_key": "mean_reproj_px",
           "std_key": "std_reproj_px", "median_key": "median_trial_reproj_px"}
    cells = [{"method": "opencv-pnp-epnp", "family": "opencv", "sigma_px": 1.0, "outlier_fraction": f,
              "mean_reproj_px": e, "std_reproj_px": e / 4, "median_trial_reproj_px": e}
             for f, e in ((0.0, 0.2), (0.3, 80.0))]
    r = {"config": {"sigmas_px": [1.0], "outlier_fractions": [0.0, 0.3], "breakdown": 2.0}, "error": err,
         "cells": cells, "breakdown": breakdown_points(cells, 2.0, "median_trial_reproj_px")}
    assert "| `opencv-pnp-epnp` | opencv | 0.2 ± 0.05 | 80 ± 20 |" in cells_table(r, sigma_px=1.0)
    assert "| `opencv-pnp-epnp` | opencv | 30% |" in breakdown_table(r)
    md = markdown(r)
    assert "exceeds 2.0 px" in md and "pose error" not in md and md.count("|---|---|") == 3
    assert [f.title for f in figures(r)] == ["Error against noise", "Error against outliers, sigma 1 px"]
