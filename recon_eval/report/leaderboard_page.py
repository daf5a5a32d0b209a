"""The leaderboard's pages: one row per run (scene, method, its headline metrics) as Markdown (the
README's tables, verbatim), and the HTML page of :mod:`recon_eval.report.leaderboard_html` (the
JSON is :func:`recon_eval.ci.leaderboard.run_leaderboard`'s)."""
from __future__ import annotations

import html
import re

from recon_eval.report import leaderboard_html

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


def html_page(doc: dict, outcomes=()) -> str:
    """The HTML page: :func:`recon_eval.report.leaderboard_html.html_page` (one sortable table per task)."""
    return leaderboard_html.html_page(doc, outcomes)
