"""``recon-eval leaderboard``: run a set of methods on a set of datasets and tabulate the headline
metrics (Markdown, JSON, HTML). A method that does not apply to a dataset (no board, no stereo
pair...) is skipped and listed as such; a method that applies but fails is a row with the error.
"""
from __future__ import annotations

import html
from pathlib import Path

from recon_eval.errors import InputError


def run_leaderboard(datasets, methods, out_dir, *, log=print) -> dict:
    from recon_eval import SCHEMA_VERSION as SV, __version__
    from recon_eval.readers.scenegen_dataset import read_dataset
    from recon_eval.runners import NotApplicable, method, run_method
    from recon_eval.runners._common import scene_name

    for m in methods:
        method(m)  # unknown names fail before anything runs
    out = Path(out_dir)
    runs, skipped = [], []
    for d in datasets:
        scene = scene_name(read_dataset(d))
        for m in methods:
            try:
                doc = run_method(m, d, out / scene / m)
            except NotApplicable as exc:
                skipped.append({"scene": scene, "method": m, "why": str(exc)})
                continue
            runs.append(doc)
            log(f"{scene:24s} {m:28s} {doc['inputs']['seconds']:7.1f} s")
    return {"schema_version": SV, "recon_eval_version": __version__, "command": "leaderboard",
            "datasets": [str(d) for d in datasets], "methods": list(methods), "runs": runs, "skipped": skipped}


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, str) and v in ("inf", "nan", "-inf"):
        return v
    return str(v)


def rows(doc: dict) -> list[tuple[str, str, str]]:
    """(scene, method, 'metric=value; ...') per run."""
    out = []
    for r in doc["runs"]:
        ms = "; ".join(f"{k} {_fmt(v)}" for k, v in r.get("metrics", {}).items())
        out.append((r["inputs"]["scene"], r["inputs"]["method"], ms))
    return out


def markdown(doc: dict) -> str:
    lines = ["| scene | method | metrics |", "|---|---|---|"]
    lines += [f"| `{s}` | `{m}` | {ms} |" for s, m, ms in rows(doc)]
    return "\n".join(lines) + "\n"


def html_page(doc: dict) -> str:
    body = "".join(f"<tr><td>{html.escape(s)}</td><td>{html.escape(m)}</td><td>{html.escape(ms)}</td></tr>"
                   for s, m, ms in rows(doc))
    return ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>recon-eval leaderboard</title>"
            "<style>td,th{border:1px solid #ccc;padding:4px;font:13px sans-serif}table{border-collapse:collapse}</style>"
            f"</head><body><h1>recon-eval leaderboard</h1><table><tr><th>scene</th><th>method</th><th>metrics</th></tr>"
            f"{body}</table></body></html>\n")


def write_all(doc: dict, out_dir) -> list[Path]:
    from recon_eval.report import write_json_atomic

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_json_atomic(out / "leaderboard.json", doc)
    (out / "leaderboard.md").write_text(markdown(doc))
    (out / "leaderboard.html").write_text(html_page(doc))
    if not doc["runs"]:
        raise InputError("leaderboard: no method applied to any dataset (see 'skipped' in leaderboard.json)")
    return [out / "leaderboard.json", out / "leaderboard.md", out / "leaderboard.html"]
