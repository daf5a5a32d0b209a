"""The leaderboard's HTML page (``leaderboard.html``): one table per task (the runs' ``inputs.task``,
:data:`recon_eval.runners.TASKS`), one row per run, one column per headline metric of that task,
sortable by clicking a header (a small inline script, no external resource; ``#sort=METRIC`` in
the address sorts by that column on opening), the best value of
each column marked per scene (direction: :func:`recon_eval.report.summary.higher_is_better`), a
cell red when its gate failed and green when it held (``outcomes``), links to each run's report
and result.json, and the skipped methods with the reason. All text is HTML-escaped.
"""
from __future__ import annotations

import html
import math
from urllib.parse import quote

from recon_eval.report.summary import fmt, higher_is_better, number

_CSS = """
body{font-family:system-ui,sans-serif;margin:2em;color:#222}
table{border-collapse:collapse;margin:0.5em 0 2em;font-size:13px}
td,th{border:1px solid #ccc;padding:3px 7px;text-align:left;white-space:nowrap}
th{background:#f0f0f0;cursor:pointer;user-select:none;white-space:normal;max-width:8em;vertical-align:bottom}
div.scroll{overflow-x:auto} th.sorted-asc::after{content:" \\25B2"}
th.sorted-desc::after{content:" \\25BC"} td.num{font-family:monospace;text-align:right}
td.best{font-weight:bold;background:#fff3c4} td.best::after{content:" \\2605";color:#b07d00}
td.pass{background:#d6f5d6} td.fail{background:#f9d2d2;color:#8a0b0b} td.missing{color:#aaa}
p.note{color:#555;font-size:13px;max-width:1000px}
"""

#: Sorts a table by the clicked column: numbers numerically (inf/nan last), else as text.
_SORT_JS = """
function sortBy(th){const table=th.closest('table'),body=table.tBodies[0],col=th.cellIndex;
const asc=!th.classList.contains('sorted-asc');
for(const h of table.tHead.rows[0].cells){h.classList.remove('sorted-asc','sorted-desc');}
th.classList.add(asc?'sorted-asc':'sorted-desc');
const key=r=>{const c=r.cells[col];const v=c.dataset.v!==undefined?c.dataset.v:c.textContent.trim();
const x=parseFloat(v);return isNaN(x)?(v===''?null:v):x;};
const rows=Array.from(body.rows);rows.sort((a,b)=>{const x=key(a),y=key(b);
if(x===null||y===null)return x===y?0:(x===null?1:-1);
if(typeof x==='number'&&typeof y==='number'){if(!isFinite(x)||!isFinite(y))return isFinite(x)?-1:(isFinite(y)?1:0);
return asc?x-y:y-x;}return asc?String(x).localeCompare(String(y)):String(y).localeCompare(String(x));});
for(const r of rows)body.appendChild(r);}
document.querySelectorAll('th').forEach(th=>th.addEventListener('click',()=>sortBy(th)));
const m=location.hash.match(/^#sort=(.+)$/);if(m){const want=decodeURIComponent(m[1]);
document.querySelectorAll('th').forEach(th=>{if(th.title===want||th.textContent===want)sortBy(th);});}
"""


def _tasks(doc: dict) -> dict:
    """task -> [(k, run)] in run order."""
    out: dict = {}
    for k, r in enumerate(doc.get("runs", [])):
        out.setdefault(str((r.get("inputs") or {}).get("task") or "other"), []).append((k, r))
    return out


def _best(runs, metric: str) -> set:
    """Indices of the runs holding the best value of ``metric`` within their scene."""
    higher = higher_is_better(metric)
    if higher is None:
        return set()
    best: dict = {}
    for k, r in runs:
        x = number((r.get("metrics") or {}).get(metric))
        if x is None or not math.isfinite(x):
            continue
        scene = (r.get("inputs") or {}).get("scene")
        cur = best.get(scene)
        if cur is None or (x > cur[0] if higher else x < cur[0]):
            best[scene] = (x, {k})
        elif x == cur[0]:
            cur[1].add(k)
    return set().union(*(ks for _, ks in best.values())) if best else set()


def _gate_status(outcomes) -> dict:
    """(run index, metric) -> "pass" | "fail" from gate outcomes on leaderboard runs (``...#runs[k]``)."""
    out = {}
    for o in outcomes:
        f = o.result_file or ""
        if "#runs[" in f:
            k = int(f.rsplit("#runs[", 1)[1].rstrip("]"))
            key = (k, o.gate.metric)
            out[key] = "fail" if (not o.passed or out.get(key) == "fail") else "pass"
    return out


def _breakable(name: str) -> str:
    """``name`` escaped, with line-break opportunities after '.' and '_' (narrow metric columns)."""
    return html.escape(name).replace(".", ".<wbr>").replace("_", "_<wbr>")


def _link(path: str | None, text: str) -> str:
    return f'<a href="{html.escape(quote(path))}">{html.escape(text)}</a>' if path else ""


def html_page(doc: dict, outcomes=()) -> str:
    """The page of a leaderboard document (module docstring); ``doc["run_dirs"][k]``: run k's folder
    relative to the page, for the links."""
    esc = html.escape
    dirs = doc.get("run_dirs") or []
    gates = _gate_status(outcomes)
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8"><title>recon-eval leaderboard</title>',
             f"<style>{_CSS}</style></head><body><h1>recon-eval leaderboard</h1>",
             (f'<p class="note">{len(doc.get("runs", []))} runs, {len(doc.get("skipped", []))} skipped. Click a header '
              "to sort. &#9733; marks the best value of a column within a scene (lower is better for errors, higher "
              "for recall, precision, ratios and scores); green / red: a gate held / failed. Definitions: "
              "docs/metrics.md, docs/ci.md.</p>")]
    for task, runs in _tasks(doc).items():
        metrics = list(dict.fromkeys(m for _, r in runs for m in (r.get("metrics") or {})))
        parts.append(f'<h2>{esc(task)}</h2><div class="scroll"><table><thead><tr><th>scene</th><th>method</th>'
                     + "".join(f'<th title="{esc(m)}">{_breakable(m)}</th>' for m in metrics)
                     + "<th>report</th></tr></thead><tbody>")
        best = {m: _best(runs, m) for m in metrics}
        for k, r in runs:
            inp = r.get("inputs") or {}
            cells = [f"<td>{esc(str(inp.get('scene')))}</td><td>{esc(str(inp.get('method')))}</td>"]
            for m in metrics:
                v = (r.get("metrics") or {}).get(m)
                x = number(v)
                cls = ["num"] + (["best"] if k in best[m] else []) + ([gates[(k, m)]] if (k, m) in gates else [])
                if v is None:
                    cells.append('<td class="num missing" data-v="">&mdash;</td>')
                    continue
                data = "" if x is None else f' data-v="{esc(repr(x))}"'
                cells.append(f'<td class="{" ".join(cls)}"{data}>{esc(fmt(v))}</td>')
            d = dirs[k] if k < len(dirs) else None
            links = " ".join(x for x in (_link(d and f"{d}/report.html", "report"),
                                         _link(d and f"{d}/result.json", "json")) if x)
            cells.append(f"<td>{links}</td>")
            parts.append("<tr>" + "".join(cells) + "</tr>")
        parts.append("</tbody></table></div>")
    skipped = doc.get("skipped") or []
    if skipped:
        parts.append("<h2>Skipped</h2><table><thead><tr><th>scene</th><th>method</th><th>why</th></tr></thead><tbody>")
        parts += [f"<tr><td>{esc(str(s.get('scene')))}</td><td>{esc(str(s.get('method')))}</td>"
                  f"<td>{esc(str(s.get('why')))}</td></tr>" for s in skipped]
        parts.append("</tbody></table>")
    parts.append(f"<script>{_SORT_JS}</script></body></html>\n")
    return "\n".join(parts)
