"""The HTML report: one self-contained file (no external resources), figures embedded as base64
PNG ``data:`` URIs. It opens with a summary (:mod:`recon_eval.report.summary`: pass / fail
coloured), then every scalar result field in a table, the inputs (provenance), the figures. All
text is HTML-escaped.

Written atomically, like the JSON report. The figures come from :mod:`recon_eval.report.plots`
(matplotlib, imported only when a figure is drawn).
"""
from __future__ import annotations

import base64
import html
from dataclasses import dataclass

from recon_eval import SCHEMA_VERSION, __version__
from recon_eval.report.document import scalar_rows, to_jsonable
from recon_eval.report.summary import summary_rows
from scenegen.dataset.files import atomic_write_bytes


@dataclass(frozen=True)
class Figure:
    title: str
    png: bytes
    caption: str = ""


_CSS = """
body{font-family:system-ui,sans-serif;margin:2em;max-width:1200px;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:13px}
td,th{border:1px solid #ccc;padding:3px 8px;text-align:left}
th{background:#f0f0f0} td.num{font-family:monospace;text-align:right}
figure{margin:1.5em 0} figcaption{font-size:13px;color:#555}
img{max-width:100%;border:1px solid #ddd}
tr.pass td.status{background:#d6f5d6;color:#0a5d0a} tr.ok td.status{background:#eef7ee;color:#3b6e3b} tr.fail td.status{background:#f9d2d2;color:#8a0b0b}
tr.fail td{background:#fdf0f0} td.status{font-weight:bold;text-transform:uppercase;font-size:11px}
p.verdict{font-size:15px;padding:6px 10px;display:inline-block;border-radius:3px}
p.verdict.pass{background:#d6f5d6} p.verdict.fail{background:#f9d2d2}
"""


def summary_html(doc: dict, outcomes=()) -> str:
    """The summary section of a result document: a verdict line and one coloured row per item."""
    esc = html.escape
    rows = summary_rows(doc, outcomes)
    n_fail = sum(r.status == "fail" for r in rows)
    n_pass = sum(r.status == "pass" for r in rows)
    n_ok = sum(r.status == "ok" for r in rows)
    verdict = "fail" if n_fail else "pass"
    gates = sum(r.name.startswith("gate ") for r in rows)
    text = ((f"{n_fail} failed" if n_fail else "nothing failed") + (f", {n_pass} of {gates} gates passed" if gates else "")
            + f", {n_ok} estimates produced, {len(rows)} items")
    parts = [f'<h2>Summary</h2><p class="verdict {verdict}">{esc(text)}</p>',
             "<table><tr><th>status</th><th>item</th><th>value</th><th>note</th></tr>"]
    for r in rows:
        parts.append(f'<tr class="{esc(r.status)}"><td class="status">{esc(r.status)}</td><td>{esc(r.name)}</td>'
                     f'<td class="num">{esc(r.value)}</td><td>{esc(r.note)}</td></tr>')
    parts.append("</table>")
    return "".join(parts)


def input_rows(inputs: dict, prefix: str = "") -> list[tuple[str, str]]:
    """The inputs as (dotted name, text) rows: nested mappings flattened, lists of plain values
    joined by spaces, so no Python repr reaches the page."""
    rows = []
    for k, v in inputs.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict) and v:
            rows += input_rows(v, name + ".")
        elif isinstance(v, (list, tuple)) and all(not isinstance(x, (dict, list, tuple)) for x in v):
            rows.append((name, " ".join(map(str, v))))
        elif isinstance(v, (list, tuple)):
            rows += input_rows({str(i): x for i, x in enumerate(v)}, name + ".")
        else:
            rows.append((name, str(v)))
    return rows


def render_html(command: str, inputs: dict, results: dict, figures: list[Figure], *, metrics: dict | None = None,
                outcomes=()) -> str:
    """The report of one command's result (``metrics``: a run's headline numbers; ``outcomes``:
    gate outcomes to show in the summary)."""
    esc = html.escape
    doc = {"command": command, "inputs": to_jsonable(inputs), "results": to_jsonable(results),
           "metrics": to_jsonable(metrics or {})}
    label = " ".join(str(doc["inputs"].get(k)) for k in ("method", "scene") if doc["inputs"].get(k))
    parts = [
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
        f"<title>recon-eval {esc(command)}{' ' + esc(label) if label else ''}</title><style>{_CSS}</style></head><body>",
        f"<h1>recon-eval {esc(command)}{': ' + esc(label) if label else ''}</h1>",
        f"<p>recon_eval {esc(__version__)}, JSON schema {esc(SCHEMA_VERSION)}. Definitions: docs/metrics.md.</p>",
        summary_html(doc, outcomes),
    ]
    parts.append("<h2>Results</h2><table><tr><th>metric</th><th>field</th><th>value</th></tr>")
    for metric, field, value in scalar_rows(results):
        parts.append(f'<tr><td>{esc(metric)}</td><td>{esc(field)}</td><td class="num">{esc(value)}</td></tr>')
    parts.append("</table><h2>Inputs</h2><table><tr><th>input</th><th>value</th></tr>")
    for k, v in input_rows(doc["inputs"]):
        parts.append(f"<tr><td>{esc(k)}</td><td>{esc(v)}</td></tr>")
    parts.append("</table>")
    if figures:
        parts.append("<h2>Figures</h2>")
    for f in figures:
        b64 = base64.b64encode(f.png).decode("ascii")
        parts.append(f'<figure><img alt="{esc(f.title)}" src="data:image/png;base64,{b64}">'
                     f"<figcaption><b>{esc(f.title)}</b>{'. ' + esc(f.caption) if f.caption else ''}</figcaption></figure>")
    parts.append("</body></html>\n")
    return "\n".join(parts)


def write_html_atomic(path, text: str) -> None:
    """Write the report atomically (:func:`scenegen.dataset.files.atomic_write`)."""
    atomic_write_bytes(path, text.encode("utf-8"))