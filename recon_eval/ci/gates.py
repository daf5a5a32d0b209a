"""CI accuracy gates over run results (``recon-eval run`` JSON, docs/ci.md).

Gate file (YAML, read by :mod:`scenegen.located_yaml`: safe loading, duplicate keys rejected, every
error names file:line: field)::

    version: 1
    gates:
      - scene: calib_checkerboard        # the results' inputs.scene ("*" = any)
        method: opencv-calib-checkerboard  # the results' inputs.method
        metric: proj_diff_rms_px         # a key of "metrics", or a dotted path into "results"
        op: "<="                         # one of < <= > >= == !=  (the operator is part of the gate)
        threshold: 0.1
        reason: mrcal-style field, 0.1 px RMS   # optional, printed with a failure

Rules (shared/notes/metrics.md, "Rules for CI gates"): a gate with no matching result, a missing
metric or a non-finite value fails; nothing is dropped silently. Baseline mode compares each gated
metric with the same scene/method/metric of stored results and fails when it got worse (in the
direction the operator says is better) by more than ``max(margin_rel * |baseline|, margin_abs)``.
"""
from __future__ import annotations

import json
import math
import operator
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

from recon_eval.errors import InputError
from scenegen.errors import SpecError
from scenegen.located_yaml import Document, Node
from scenegen.located_yaml.source import read_source

OPS = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge, "==": operator.eq,
       "!=": operator.ne}


@dataclass(frozen=True)
class Gate:
    scene: str
    method: str
    metric: str
    op: str
    threshold: float
    reason: str
    where: str  # file:line of the gate

    @property
    def name(self) -> str:
        return f"{self.scene}/{self.method}/{self.metric} {self.op} {self.threshold:g}"


@dataclass(frozen=True)
class GateOutcome:
    gate: Gate
    passed: bool
    value: float | None  # None: no result or no such metric
    message: str
    result_file: str | None


def load_gates(path) -> list[Gate]:
    """Parse and validate a gate file; errors name file:line: field."""
    p = Path(path)
    try:
        text = read_source(p, "gate file")  # size limit, UTF-8, one-line errors
        return _gates(Document(text, str(p), p.parent).root)
    except SpecError as exc:  # the located-YAML layer's error, as recon_eval's bad input
        raise InputError(str(exc)) from None


def _gates(root: Node) -> list[Gate]:
    doc = root.as_mapping("a mapping with 'version' and 'gates'").check(required=("version", "gates"))
    version = doc.req("version")
    if version.scalar() != 1 or isinstance(version.scalar(), bool):
        raise version.error(f"expected 1, got {version.describe()}")
    items = doc.req("gates").items("a non-empty list of gates")
    if not items:
        raise doc.req("gates").error("expected a non-empty list of gates")
    return [_gate(item) for item in items]


def _gate(item: Node) -> Gate:
    g = item.as_mapping("a mapping (scene, method, metric, op, threshold)").check(
        required=("method", "metric", "op", "threshold"), optional=("scene", "reason"))
    names = {k: g.req(k).as_str() for k in ("method", "metric")}
    scene = g.get("scene").as_str() if g.get("scene") is not None else "*"
    op = g.req("op").as_enum(list(OPS), "the comparison operator")
    thr = g.req("threshold")
    try:
        threshold = thr.as_float()
    except SpecError:
        raise thr.error(f"expected a finite number, got {thr.describe()}") from None
    reason = g.get("reason")
    return Gate(scene, names["method"], names["metric"], op, threshold,
                "" if reason is None else str(reason.scalar()), f"{item.doc.file}:{item.line}")


def load_results(paths) -> list[tuple[str, dict]]:
    """Run-result JSON files (``command: "run"``) or leaderboard JSON files (their ``runs``)."""
    out = []
    for path in paths:
        p = Path(path)
        try:
            doc = json.loads(p.read_text())
        except OSError as exc:
            raise InputError(f"{p}: cannot read ({exc.strerror})") from None
        except json.JSONDecodeError as exc:
            raise InputError(f"{p}:{exc.lineno}: invalid JSON: {exc.msg}") from None
        except RecursionError:
            raise InputError(f"{p}: invalid JSON: nested too deeply") from None
        if isinstance(doc, dict) and doc.get("command") == "run":
            out.append((str(p), doc))
        elif isinstance(doc, dict) and doc.get("command") == "leaderboard":
            out += [(f"{p}#runs[{k}]", r) for k, r in enumerate(doc.get("runs", []))]
        else:
            raise InputError(f"{p}: command: expected a 'recon-eval run' or 'recon-eval leaderboard' result JSON")
    return out


def _flatten(d, prefix="", out=None):
    out = {} if out is None else out
    if isinstance(d, dict):
        for k, v in d.items():
            _flatten(v, f"{prefix}.{k}" if prefix else str(k), out)
    else:
        out[prefix] = d
    return out


def metric_value(doc: dict, metric: str):
    """The metric's value: ``metrics[metric]``, else the dotted path into ``results``; None if absent.
    JSON's "inf"/"nan" strings become floats."""
    v = doc.get("metrics", {}).get(metric)
    if v is None:
        v = _flatten(doc.get("results", {})).get(metric)
    if isinstance(v, str) and v in ("inf", "-inf", "nan"):
        return float(v)
    if isinstance(v, bool):
        return float(v)
    return float(v) if isinstance(v, (int, float)) else None


def _matches(g: Gate, doc: dict) -> bool:
    inp = doc.get("inputs", {})
    return inp.get("method") == g.method and (g.scene == "*" or inp.get("scene") == g.scene)


def evaluate(gates, results) -> list[GateOutcome]:
    out = []
    for g in gates:
        hits = [(f, d) for f, d in results if _matches(g, d)]
        if not hits:
            out.append(GateOutcome(g, False, None, f"FAIL {g.name}: no result for scene {g.scene!r} method "
                                                  f"{g.method!r} (missing results fail)", None))
            continue
        for f, d in hits:
            v = metric_value(d, g.metric)
            if v is None:
                out.append(GateOutcome(g, False, None, f"FAIL {g.metric}: no such metric in {f} "
                                                      f"(scene {g.scene}, method {g.method})", f))
            elif not math.isfinite(v):
                out.append(GateOutcome(g, False, v, f"FAIL {g.metric} = {v} (non-finite) vs threshold {g.op} "
                                                   f"{g.threshold:g} [{g.scene} / {g.method}]", f))
            else:
                ok = OPS[g.op](v, g.threshold)
                msg = (f"{'ok  ' if ok else 'FAIL'} {g.metric} = {v:.6g}, threshold {g.op} {g.threshold:g} "
                       f"[{d['inputs'].get('scene')} / {g.method}]" + (f" ({g.reason})" if g.reason and not ok else ""))
                out.append(GateOutcome(g, ok, v, msg, f))
    return out


def compare_baseline(gates, results, baseline, *, margin_rel: float, margin_abs: float) -> list[GateOutcome]:
    """Per gated metric: fail when the current value is worse than the baseline's by more than
    max(margin_rel * |baseline|, margin_abs). 'Worse' follows the gate's operator (< and <=: lower
    is better; > and >=: higher is better; == and != have no direction and are skipped)."""
    out = []
    for g in gates:
        if g.op not in ("<", "<=", ">", ">="):
            continue
        lower_better = g.op in ("<", "<=")
        for f, d in results:
            if not _matches(g, d):
                continue
            scene = d["inputs"].get("scene")
            base = [b for _, b in baseline if b["inputs"].get("method") == g.method and b["inputs"].get("scene") == scene]
            name = f"baseline {scene}/{g.method}/{g.metric}"
            bg = Gate(scene, g.method, g.metric, g.op, g.threshold, g.reason, g.where)
            if not base:
                out.append(GateOutcome(bg, False, None, f"FAIL {name}: no baseline result", f))
                continue
            v, b = metric_value(d, g.metric), metric_value(base[0], g.metric)
            if v is None or b is None or not math.isfinite(b):
                out.append(GateOutcome(bg, False, v, f"FAIL {g.metric}: missing or non-finite in current ({v}) or "
                                                     f"baseline ({b}) [{scene} / {g.method}]", f))
                continue
            allowed = max(margin_rel * abs(b), margin_abs)
            worse = (v - b) if lower_better else (b - v)
            ok = math.isfinite(v) and worse <= allowed
            out.append(GateOutcome(bg, ok, v, f"{'ok  ' if ok else 'FAIL'} {g.metric} = {v:.6g} vs baseline {b:.6g}: "
                                              f"worse by {worse:.6g}, allowed {allowed:.6g} [{scene} / {g.method}]", f))
    return out


def junit_xml(outcomes, suite: str = "recon-eval gates") -> str:
    fails = sum(not o.passed for o in outcomes)
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<testsuites><testsuite name={quoteattr(suite)} tests="{len(outcomes)}" failures="{fails}" errors="0">']
    for o in outcomes:
        g = o.gate
        lines.append(f'  <testcase classname={quoteattr(f"{g.scene}.{g.method}")} name={quoteattr(f"{g.metric} {g.op} {g.threshold:g}")}>')
        if not o.passed:
            lines.append(f'    <failure message={quoteattr(o.message)} type="GateFailure">{o.gate.where}</failure>')
        lines.append("  </testcase>")
    lines.append("</testsuite></testsuites>")
    return "\n".join(lines) + "\n"
