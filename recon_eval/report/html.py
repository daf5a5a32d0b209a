"""The HTML report: one self-contained file (no external resources), figures embedded as base64
PNG ``data:`` URIs, every scalar result field in a table, inputs (provenance) listed.

Written atomically, like the JSON report. The figures come from :mod:`recon_eval.report.plots`
(matplotlib, imported only when a figure is drawn).
"""
from __future__ import annotations

import base64
import html
from dataclasses import dataclass

from recon_eval import SCHEMA_VERSION, __version__
from recon_eval.report.document import scalar_rows, to_jsonable
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
"""


def render_html(command: str, inputs: dict, results: dict, figures: list[Figure]) -> str:
    esc = html.escape
    parts = [
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
        f"<title>recon-eval {esc(command)}</title><style>{_CSS}</style></head><body>",
        f"<h1>recon-eval {esc(command)}</h1>",
        f"<p>recon_eval {esc(__version__)}, JSON schema {esc(SCHEMA_VERSION)}. Definitions: docs/metrics.md.</p>",
        "<h2>Inputs</h2><table><tr><th>input</th><th>value</th></tr>",
    ]
    for k, v in to_jsonable(inputs).items():
        parts.append(f"<tr><td>{esc(str(k))}</td><td>{esc(str(v))}</td></tr>")
    parts.append("</table><h2>Results</h2><table><tr><th>metric</th><th>field</th><th>value</th></tr>")
    for metric, field, value in scalar_rows(results):
        parts.append(f'<tr><td>{esc(metric)}</td><td>{esc(field)}</td><td class="num">{esc(value)}</td></tr>')
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