"""CI accuracy gates over result JSON files (docs/ci.md).

Any result JSON of recon-eval is gated: a scoring command's ``--json`` (``fmatrix``, ``disparity``,
``poses``, ``pnp``, ``features``, ``flow``, ``calibration``, ...), ``recon-eval run``'s
``result.json`` and the runs of a ``leaderboard.json``. Gate file (YAML, read by
:mod:`scenegen.located_yaml`: safe loading, duplicate keys rejected, every error names
file:line: field)::

    version: 1
    gates:
      - scene: calib_checkerboard        # the results' inputs.scene (fnmatch pattern; absent = "*")
        method: opencv-calib-checkerboard  # the results' inputs.method (fnmatch pattern)
        command: run                     # optional: the command that wrote the JSON (pattern; absent = "*")
        metric: proj_diff_rms_px         # a metric path (:mod:`recon_eval.ci.metric_paths`)
        op: "<="                         # one of < <= > >= == !=  (the operator is part of the gate)
        threshold: 0.1
        reason: mrcal-style field, 0.1 px RMS   # optional, printed with a failure

A result without a method or scene (a scoring command run without ``--method``, a truth that is
not a dataset) is matched only by ``"*"``. Rules (shared/notes/metrics.md, "Rules for CI gates"):
a gate with no matching result, a missing metric or a non-finite value fails; nothing is dropped
silently. Baseline mode compares each gated metric with the same command/scene/method/metric of
stored results and fails when it got worse (in the direction the operator says is better) by more
than ``max(margin_rel * |baseline|, margin_abs)``.
"""
from __future__ import annotations

import json
import math
import operator
from dataclasses import dataclass
from fnmatch import fnmatchcase
from pathlib import Path
from xml.sax.saxutils import quoteattr

from recon_eval.ci.metric_paths import resolve
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
    command: str = "*"  # the command that wrote the result JSON (fnmatch pattern)

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
        required=("method", "metric", "op", "threshold"), optional=("scene", "command", "reason"))
    names = {k: g.req(k).as_str() for k in ("method", "metric")}
    if not names["metric"].strip():
        raise g.req("metric").error("expected a metric path (docs/ci.md, 'Metric paths'), got an empty string")
    scene = g.get("scene").as_str() if g.get("scene") is not None else "*"
    command = g.get("command").as_str() if g.get("command") is not None else "*"
    op = g.req("op").as_enum(list(OPS), "the comparison operator")
    thr = g.req("threshold")
    try:
        threshold = thr.as_float()
    except SpecError:
        raise thr.error(f"expected a finite number, got {thr.describe()}") from None
    reason = g.get("reason")
    return Gate(scene, names["method"], names["metric"], op, threshold,
                "" if reason is None else str(reason.scalar()), f"{item.doc.file}:{item.line}", command)


def load_results(paths) -> list[tuple[str, dict]]:
    """Result JSON files of any recon-eval command (a scoring command's ``--json``, ``run``'s
    ``result.json``), and the runs of leaderboard JSON files."""
    out = []
    for path in paths:
        p = Path(path)
        try:
            doc = json.loads(p.read_text())
        except OSError as exc:
            raise InputError(f"{p}: cannot read ({exc.strerror})") from None
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise InputError(f"{p}:{getattr(exc, 'lineno', 1)}: invalid JSON: {getattr(exc, 'msg', exc)}") from None
        except RecursionError:
            raise InputError(f"{p}: invalid JSON: nested too deeply") from None
        if isinstance(doc, dict) and doc.get("command") == "leaderboard" and isinstance(doc.get("runs"), list):
            out += [(f"{p}#runs[{k}]", r) for k, r in enumerate(doc["runs"]) if isinstance(r, dict)]
        elif (isinstance(doc, dict) and isinstance(doc.get("command"), str) and isinstance(doc.get("results"), dict)
              and isinstance(doc.get("inputs", {}), dict)):
            out.append((str(p), doc))
        else:
            raise InputError(f"{p}: expected a recon-eval result JSON (an object with 'command' and 'results': the "
                             f"--json of a scoring command, run's result.json, or leaderboard.json)")
    return out


def identity(doc: dict) -> tuple:
    """(command, method, scene) of a result document; None where it does not say."""
    inp = doc.get("inputs") or {}
    ident = (doc.get("command"), inp.get("method"), inp.get("scene"))
    return tuple(x if isinstance(x, str) and x else None for x in ident)


def metric_value(doc: dict, metric: str):
    """The number the metric path ``metric`` names in ``doc`` (:func:`recon_eval.ci.metric_paths.resolve`),
    or None when it names none."""
    return resolve(doc, metric).value


def _matches(g: Gate, doc: dict) -> bool:
    command, method, scene = identity(doc)
    return all(pat == "*" or (val is not None and fnmatchcase(val, pat))
               for pat, val in ((g.command, command), (g.method, method), (g.scene, scene)))


def _label(doc: dict) -> str:
    command, method, scene = identity(doc)
    return f"{scene or '-'} / {method or '-'}" + ("" if command == "run" else f" ({command})")


def evaluate(gates, results) -> list[GateOutcome]:
    out = []
    for g in gates:
        hits = [(f, d) for f, d in results if _matches(g, d)]
        if not hits:
            cmd = "" if g.command == "*" else f" command {g.command!r}"
            out.append(GateOutcome(g, False, None, f"FAIL {g.name}: no result for scene {g.scene!r} method "
                                                  f"{g.method!r}{cmd} (missing results fail; gate {g.where})", None))
            continue
        for f, d in hits:
            look = resolve(d, g.metric)
            v = look.value
            if v is None:
                out.append(GateOutcome(g, False, None, f"FAIL {g.metric}: {look.problem} in {f} [{_label(d)}] "
                                                      f"(gate {g.where})", f))
            elif not math.isfinite(v):
                out.append(GateOutcome(g, False, v, f"FAIL {g.metric} = {v} (non-finite) vs threshold {g.op} "
                                                   f"{g.threshold:g} [{_label(d)}] (gate {g.where})", f))
            else:
                ok = OPS[g.op](v, g.threshold)
                msg = (f"{'ok  ' if ok else 'FAIL'} {g.metric} = {v:.6g}, threshold {g.op} {g.threshold:g} "
                       f"[{_label(d)}]" + (f" ({g.reason})" if g.reason and not ok else "")
                       + ("" if ok else f" (gate {g.where})"))
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
            command, method, scene = identity(d)
            base = [b for _, b in baseline if identity(b) == (command, method, scene)]
            name = f"baseline {scene}/{method}/{g.metric}"
            bg = Gate(scene or "-", method or "-", g.metric, g.op, g.threshold, g.reason, g.where, command or "-")
            if not base:
                out.append(GateOutcome(bg, False, None, f"FAIL {name}: no baseline result", f))
                continue
            v, b = metric_value(d, g.metric), metric_value(base[0], g.metric)
            if v is None or b is None or not math.isfinite(b):
                out.append(GateOutcome(bg, False, v, f"FAIL {g.metric}: missing or non-finite in current ({v}) or "
                                                     f"baseline ({b}) [{_label(d)}]", f))
                continue
            allowed = max(margin_rel * abs(b), margin_abs)
            worse = (v - b) if lower_better else (b - v)
            ok = math.isfinite(v) and worse <= allowed
            out.append(GateOutcome(bg, ok, v, f"{'ok  ' if ok else 'FAIL'} {g.metric} = {v:.6g} vs baseline {b:.6g}: "
                                              f"worse by {worse:.6g}, allowed {allowed:.6g} [{_label(d)}]", f))
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
