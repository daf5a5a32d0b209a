"""``recon-eval leaderboard``: run a set of methods on a set of datasets and tabulate the headline
metrics (Markdown, JSON, HTML; pages: :mod:`recon_eval.report.leaderboard_page`). A method that
does not apply to a dataset (no board, no stereo pair...) is skipped and listed as such; a method
that applies but fails is a row with the error.
"""
from __future__ import annotations

from pathlib import Path

from recon_eval import SCHEMA_VERSION, __version__
from recon_eval.errors import InputError, NotApplicable
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.report.document import write_json_atomic
from recon_eval.report.html import render_html, write_html_atomic
from recon_eval.report.leaderboard_page import html_page, markdown
from recon_eval.runners import REPORT, method, run_method
from scenegen.dataset.layout import check_name


def run_leaderboard(datasets, methods, out_dir, *, log=print, declared: dict | None = None) -> dict:
    """Every method (built-in, or one of the user's ``declared`` methods) on every dataset."""
    for m in methods:
        method(m, declared)  # unknown names fail before anything runs
    out = Path(out_dir)
    runs, skipped, dirs = [], [], []
    for d in datasets:
        scene = read_dataset(d).scene_name
        try:
            check_name("scene", scene)  # it becomes a folder under out_dir: no '/', no '..'
        except ValueError as exc:
            raise InputError(f"{d}: the dataset's scene name cannot be a folder name: {exc}") from None
        for m in methods:
            try:
                doc = run_method(m, d, out / scene / m, declared=declared)
            except NotApplicable as exc:
                skipped.append({"scene": scene, "method": m, "why": str(exc)})
                continue
            runs.append(doc)
            dirs.append(f"{scene}/{m}")
            log(f"{scene:24s} {m:28s} {doc['inputs']['seconds']:7.1f} s")
    return {"schema_version": SCHEMA_VERSION, "recon_eval_version": __version__, "command": "leaderboard",
            "datasets": [str(d) for d in datasets], "methods": list(methods), "runs": runs, "skipped": skipped,
            "run_dirs": dirs}


def write_all(doc: dict, out_dir, outcomes=()) -> list[Path]:
    """leaderboard.json, .md and .html (``outcomes``: gate outcomes on the runs, coloured in the page)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_json_atomic(out / "leaderboard.json", doc)
    (out / "leaderboard.md").write_text(markdown(doc))
    (out / "leaderboard.html").write_text(html_page(doc, outcomes))
    for k, run_dir in enumerate(doc.get("run_dirs", [])):  # each run's report with its gate outcomes
        mine = [o for o in outcomes if o.result_file and o.result_file.endswith(f"#runs[{k}]")]
        if mine:
            r = doc["runs"][k]
            write_html_atomic(out / run_dir / REPORT, render_html("run", r["inputs"], r["results"], [],
                                                                  metrics=r["metrics"], outcomes=mine))
    if not doc["runs"]:
        raise InputError("leaderboard: no method applied to any dataset (see 'skipped' in leaderboard.json)")
    return [out / "leaderboard.json", out / "leaderboard.md", out / "leaderboard.html"]
