"""The leaderboard's pages: one row per run (scene, method, its headline metrics), as Markdown and
as a self-contained HTML table (the JSON is :func:`recon_eval.ci.leaderboard.run_leaderboard`'s)."""
from __future__ import annotations

import html
import re

_NAME = re.compile(r"[A-Za-z0-9_.-]+")


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, str) and v in ("inf", "nan", "-inf"):
        return v
    return str(v)


def rows(doc: dict) -> list[tuple[str, str, str]]:
    """(scene, method, 'metric=value; ...') per run of a leaderboard document."""
    out = []
    for r in doc["runs"]:
        ms = "; ".join(f"{k} {_fmt(v)}" for k, v in r.get("metrics", {}).items())
        out.append((r["inputs"]["scene"], r["inputs"]["method"], ms))
    return out


def markdown_text(text: str) -> str:
    """``text`` as plain Markdown table-cell text: HTML escaped (no raw ``<script>`` from a name
    or an error message), the cell separator and code marks backslash-escaped, on one line."""
    text = html.escape(" ".join(str(text).split()), quote=False)
    return "".join("\\" + c if c in "\\`|" else c for c in text)


def markdown_name(name: str) -> str:
    """A scene or method name as a code span when it is made of name characters, else as text."""
    return f"`{name}`" if _NAME.fullmatch(str(name)) else markdown_text(name)


def markdown(doc: dict) -> str:
    lines = ["| scene | method | metrics |", "|---|---|---|"]
    lines += [f"| {markdown_name(s)} | {markdown_name(m)} | {markdown_text(ms)} |" for s, m, ms in rows(doc)]
    return "\n".join(lines) + "\n"


def html_page(doc: dict) -> str:
    body = "".join(f"<tr><td>{html.escape(s)}</td><td>{html.escape(m)}</td><td>{html.escape(ms)}</td></tr>"
                   for s, m, ms in rows(doc))
    return ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>recon-eval leaderboard</title>"
            "<style>td,th{border:1px solid #ccc;padding:4px;font:13px sans-serif}table{border-collapse:collapse}</style>"
            f"</head><body><h1>recon-eval leaderboard</h1><table><tr><th>scene</th><th>method</th><th>metrics</th></tr>"
            f"{body}</table></body></html>\n")
