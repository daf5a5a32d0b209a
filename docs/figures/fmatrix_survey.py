"""Figures of docs/fmatrix_survey.md: error against noise and against outliers per method family,
from a sweep's result (``recon-eval sweep ... -o OUT``), the same figures as its report.html.

    .venv/bin/python docs/figures/fmatrix_survey.py OUT/sweep.json

writes docs/figures/fmatrix_survey_noise.png and docs/figures/fmatrix_survey_outliers_<sigma>px.png.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from recon_eval.report.sweep_report import figures

HERE = Path(__file__).resolve().parent


def main(path: str) -> None:
    results = json.loads(Path(path).read_text())["results"]
    for fig in figures(results):
        name = "noise" if fig.title == "Error against noise" else "outliers_" + fig.title.split()[-2].replace(".", "_") + "px"
        out = HERE / f"fmatrix_survey_{name}.png"
        out.write_bytes(fig.png)
        print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1])
