"""One metric-path scheme for every recon-eval result JSON (docs/ci.md, "Metric paths").

Every JSON recon-eval writes (a scoring command's ``--json``, ``recon-eval run``'s ``result.json``,
one run of a ``leaderboard.json``) has ``results``: result group -> fields (objects nest); a run
adds ``metrics``: its flat headline numbers. A metric path names one number of it:

1. a key of ``metrics`` (``synthetic.sampson_rms_px``, ``fx_rel_err``), else
2. the dotted path into ``results``, without the ``results.`` prefix: group, then field, then
   nested fields or list indices (``fundamental.sampson_rms_px``, ``pnp.rot_err_deg``,
   ``eth3d@0.01m.f1``: group names may themselves hold dots, the path is matched whole).

The prefixed forms ``results.<path>`` and ``metrics.<key>`` are accepted when they name exactly
one number (nothing else is called that); otherwise the lookup says which path to write.
"""
from __future__ import annotations

from dataclasses import dataclass
from difflib import get_close_matches

#: Prefixes a user may write in front of a path (the JSON's own key names).
PREFIXES = ("results.", "metrics.")


@dataclass(frozen=True)
class Lookup:
    """The outcome of resolving a metric path in one result document."""

    value: float | None  # None: not found, ambiguous, or not a number
    path: str  # the path that was resolved (the canonical form)
    problem: str = ""  # why value is None, naming the right path where one exists


def flatten(d, prefix: str = "", out: dict | None = None, clashes: set | None = None) -> tuple[dict, set]:
    """(dotted path -> leaf value, paths that two different leaves share) of a JSON value; lists
    are indexed ``path.0``, ``path.1``..."""
    out = {} if out is None else out
    clashes = set() if clashes is None else clashes
    items = d.items() if isinstance(d, dict) else enumerate(d) if isinstance(d, list) else None
    if items is None:
        if prefix in out:
            clashes.add(prefix)
        out[prefix] = d
        return out, clashes
    for k, v in items:
        flatten(v, f"{prefix}.{k}" if prefix else str(k), out, clashes)
    return out, clashes


def _number(v):
    if isinstance(v, str) and v in ("inf", "-inf", "nan"):  # how recon-eval writes non-finite numbers
        return float(v)
    if isinstance(v, bool):
        return float(v)
    return float(v) if isinstance(v, (int, float)) else None


def _find(doc: dict, path: str, flat: dict, clashes: set):
    """(found, value, problem) of one exact path."""
    metrics = doc.get("metrics") or {}
    if path in metrics:
        return True, metrics[path], ""
    if path in clashes:
        return True, None, f"{path!r} names more than one value in results (group names with dots)"
    if path in flat:
        return True, flat[path], ""
    return False, None, ""


def available_paths(doc: dict) -> list[str]:
    """Every metric path of ``doc`` that names a number (headline metrics first)."""
    flat, _ = flatten(doc.get("results") or {})
    heads = [k for k, v in (doc.get("metrics") or {}).items() if _number(v) is not None]
    return heads + [k for k, v in flat.items() if _number(v) is not None and k not in heads]


def resolve(doc: dict, metric: str) -> Lookup:
    """The number ``metric`` names in the result document ``doc`` (module docstring)."""
    flat, clashes = flatten(doc.get("results") or {})
    found, v, problem = _find(doc, metric, flat, clashes)
    for pre in PREFIXES:
        if not metric.startswith(pre):
            continue
        rest = metric[len(pre):]
        f2, v2, p2 = _find(doc, rest, flat, clashes)
        if found and f2:
            return Lookup(None, metric, f"{metric!r} is ambiguous: both {metric!r} and {rest!r} exist; "
                                        f"metric paths are relative to results (write {rest!r})")
        if f2:
            found, v, problem, metric = True, v2, p2, rest
    if not found:
        close = get_close_matches(metric.removeprefix("results.").removeprefix("metrics."), available_paths(doc),
                                  n=3, cutoff=0.5)
        hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else ""
        return Lookup(None, metric, f"no metric {metric!r}{hint}")
    if problem:
        return Lookup(None, metric, problem)
    x = _number(v)
    return Lookup(x, metric, "" if x is not None else f"{metric!r} is not a number ({type(v).__name__})")
