"""Figures of docs/fmatrix_survey.md: error against noise and against outliers per method family,
from a sweep's result (``recon-eval sweep ... -o OUT``), the same figures as its report.html.

    .venv/bin/python docs/figures/fmatrix_survey.py OUT/sweep.json [PREFIX]

writes docs/figures/<PREFIX>_noise.png and <PREFIX>_outliers_<sigma>px.png (PREFIX default
fmatrix_survey) and prints the Markdown tables (as ``recon-eval sweep --markdown``).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from recon_eval.report.sweep_report import figures, markdown

HERE = Path(__file__).resolve().parent


def main(path: str, prefix: str = "fmatrix_survey") -> None:
    results = json.loads(Path(path).read_text())["results"]
    for fig in figures(results):
        sigma = fig.title.split()[-2].replace(".", "_")
        name = "noise" if fig.title == "Error against noise" else f"outliers_{sigma}px"
        out = HERE / f"{prefix}_{name}.png"
        out.write_bytes(fig.png)
        print(f"wrote {out}", file=sys.stderr)
    print(markdown(results))


if __name__ == "__main__":
    main(*sys.argv[1:3])
