"""What an HTML page says first: the summary rows of a result, each with a pass/fail status, and
which direction is better for a metric (the leaderboard's best values). A run's summary lists its
headline metrics and every result group with a ``failed`` flag; a scoring command's, each result
group with its first :data:`FIELDS_PER_GROUP` numbers.

Status of a summary row: ``fail`` for a failed estimate (a result group with ``failed: true``,
a non-finite headline number, an external method's failed invocation in the notes), ``ok`` for a
result group that has a ``failed`` flag and it is false (an estimate was produced; how good it is
says a gate), ``info`` otherwise (a number without a threshold is neither). A gate outcome (:class:`recon_eval.ci.gates.GateOutcome`-like: ``passed``,
``value``, ``gate``) is ``pass`` or ``fail`` by its threshold.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

#: Fields shown per result group in a scoring command's summary (the full table follows it).
FIELDS_PER_GROUP = 4

#: (pattern on the metric's last path part, True if higher is better, None if neither), first match
#: wins; a metric matching none has no best value either. A signed error (a bias) is best at 0,
#: which no direction says: its absolute value is the ranked column.
DIRECTIONS = (
    (re.compile(r"^(?!abs_).*signed"), None),
    (re.compile(r"failure|invalid|outlier"), False),
    (re.compile(r"recall|precision|ratio|mma|repeatab|matching_score|accuracy|auc|fscore|f_score|^f1$|"
                r"completeness|^n_|^a[123]$|registered|inlier|^within_|coverage|^bop19_ar|^coco_kp_a[pr]|^pck"), True),
    (re.compile(r"err|rms|bad_|dist|mace|mae|epe|abs_rel|sq_rel|^fl_|_pct$|_px$|_deg$|_m$|chamfer|sampson"), False),
)


@dataclass(frozen=True)
class SummaryRow:
    name: str
    value: str
    status: str  # "pass" | "fail" (gates, failed estimates) | "ok" | "info"
    note: str = ""


def higher_is_better(metric: str) -> bool | None:
    """True/False by :data:`DIRECTIONS` on the metric's last dotted part; None when unknown."""
    last = metric.rsplit(".", 1)[-1].lower()
    for pattern, higher in DIRECTIONS:
        if pattern.search(last):
            return higher
    return None


def number(v) -> float | None:
    if isinstance(v, bool):
        return None
    if isinstance(v, str) and v in ("inf", "-inf", "nan"):
        return float(v)
    return float(v) if isinstance(v, (int, float)) else None


def fmt(v) -> str:
    x = number(v)
    return f"{x:.4g}" if x is not None and not isinstance(v, int) else str(v)


def _group_rows(name: str, group) -> list[SummaryRow]:
    if not isinstance(group, dict):
        x = number(group)
        return [] if x is None else [SummaryRow(name, fmt(group), "fail" if not math.isfinite(x) else "info")]
    failed = group.get("failed")
    fields = [(k, v) for k, v in group.items() if number(v) is not None][:FIELDS_PER_GROUP]
    shown = ", ".join(f"{k} {fmt(v)}" for k, v in fields)
    if isinstance(failed, bool):
        why = group.get("failure_reason") or group.get("reason") or ""
        return [SummaryRow(name, shown, "fail" if failed else "ok", f"failed: {why}" if failed and why else
                           ("failed" if failed else "estimate produced"))]
    return [SummaryRow(name, shown, "info")] if shown else []


def summary_rows(doc: dict, outcomes=()) -> list[SummaryRow]:
    """The summary of a result document (module docstring): gate outcomes first, then a run's
    headline metrics or a scoring command's result groups, then failed items in the notes."""
    rows = [SummaryRow(f"gate {o.gate.metric} {o.gate.op} {o.gate.threshold:g}",
                       "missing" if o.value is None else fmt(o.value), "pass" if o.passed else "fail", o.gate.where)
            for o in outcomes]
    notes = (doc.get("inputs") or {}).get("notes") or {}
    crashed = {str(item): note for item, note in (notes.items() if isinstance(notes, dict) else ())
               if isinstance(note, dict) and note.get("failed")}
    rows += _item_rows(doc)
    # an item whose command failed is one row (below), not one more per number it left at inf
    hidden = [r for r in rows[len(outcomes):] if r.name.split(".", 1)[0] in crashed]
    rows = [r for r in rows if r not in hidden]
    for item, note in crashed.items():
        tail = note.get("stderr_tail") or []
        n = sum(1 for r in hidden if r.name.split(".", 1)[0] == item)
        rows.append(SummaryRow(item, "failed", "fail", f"{note['failed']}" + (f": {tail[-1]}" if tail else "")
                               + (f" (no estimate: {n} result rows folded into this one)" if n else "")))
    return rows


def _item_rows(doc: dict) -> list[SummaryRow]:
    """A run's headline metrics and failed flags, or a scoring command's result groups."""
    rows: list[SummaryRow] = []
    metrics = doc.get("metrics")
    if isinstance(metrics, dict) and metrics:
        for k, v in metrics.items():
            x = number(v)
            rows.append(SummaryRow(k, fmt(v), "fail" if x is None or not math.isfinite(x) else "info"))
        for name, group in (doc.get("results") or {}).items():  # a run: its estimates' failed flags
            if isinstance(group, dict) and isinstance(group.get("failed"), bool):
                rows += _group_rows(str(name), group)
    else:
        for name, group in (doc.get("results") or {}).items():
            rows += _group_rows(str(name), group)
    return rows
