"""The ``run``, ``leaderboard`` and ``gate`` subcommands of ``recon-eval`` (wired into
:mod:`recon_eval.cli`). Exit codes: 0 ok / all gates hold, 1 a gate failed, 2 bad input."""
from __future__ import annotations

import sys

COMMANDS = ("run", "leaderboard", "gate")


def add_parsers(sub) -> None:
    p = sub.add_parser("run", help="run an estimator on a dataset, keep its raw output, score it",
                       description="Run METHOD on DATASET; raw output and result.json go to -o RESULTS.")
    p.add_argument("method", help="method name (recon-eval run --list shows them)", nargs="?")
    p.add_argument("dataset", nargs="?", help="scenegen dataset folder")
    p.add_argument("-o", "--out", help="results folder (raw outputs + result.json)")
    p.add_argument("--list", action="store_true", help="list the methods and exit")
    p.add_argument("--quiet", action="store_true")
    p = sub.add_parser("leaderboard", help="run methods on datasets; write leaderboard.md/.json/.html",
                       description="Run every METHOD on every DATASET (inapplicable pairs are skipped).")
    p.add_argument("--datasets", nargs="+", required=True, help="scenegen dataset folders")
    p.add_argument("--methods", nargs="+", required=True, help="method names")
    p.add_argument("-o", "--out", required=True, help="output folder")
    p = sub.add_parser("gate", help="check run results against a gate file (exit 1 when any gate fails)",
                       description="Check results against GATES; exit 0 all hold, 1 any fails, 2 bad input.")
    p.add_argument("gates", help="gate file (YAML, docs/ci.md)")
    p.add_argument("results", nargs="+", help="result.json of 'recon-eval run' or leaderboard.json files")
    p.add_argument("--junit", metavar="OUT.xml", help="write a JUnit XML report")
    p.add_argument("--baseline", action="append", metavar="STORED.json",
                   help="stored results: also fail when a gated metric worsens by more than the margin")
    p.add_argument("--margin", type=float, default=0.10, help="baseline: allowed relative worsening (default 0.10)")
    p.add_argument("--margin-abs", type=float, default=0.0, help="baseline: allowed absolute worsening (default 0)")


def handle(a) -> int:
    from recon_eval.errors import InputError

    try:
        if a.command == "run":
            return _run(a)
        if a.command == "leaderboard":
            return _leaderboard(a)
        return _gate(a)
    except InputError as exc:
        print(f"recon-eval: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"recon-eval: error: {exc.filename or ''}: {exc.strerror or exc}", file=sys.stderr)
        return 2


def _run(a) -> int:
    from recon_eval.errors import InputError
    from recon_eval.runners import METHODS, run_method

    if a.list:
        for m in METHODS.values():
            print(f"{m.name:28s} {m.description}")
        return 0
    if not (a.method and a.dataset and a.out):
        raise InputError("run needs METHOD DATASET -o RESULTS (or --list)")
    doc = run_method(a.method, a.dataset, a.out)
    if not a.quiet:
        from rich.console import Console
        from rich.table import Table

        t = Table(title=f"recon-eval run {a.method} ({doc['inputs']['scene']})")
        t.add_column("metric")
        t.add_column("value")
        for k, v in doc["metrics"].items():
            t.add_row(k, f"{v:.6g}" if isinstance(v, float) else str(v))
        Console().print(t)
    return 0


def _leaderboard(a) -> int:
    from recon_eval.leaderboard import run_leaderboard, write_all

    doc = run_leaderboard(a.datasets, a.methods, a.out)
    for p in write_all(doc, a.out):
        print(f"wrote {p}")
    return 0


def _gate(a) -> int:
    from pathlib import Path

    from recon_eval.gates import compare_baseline, evaluate, junit_xml, load_gates, load_results

    gates = load_gates(a.gates)
    results = load_results(a.results)
    outcomes = evaluate(gates, results)
    if a.baseline:
        outcomes += compare_baseline(gates, results, load_results(a.baseline), margin_rel=a.margin,
                                     margin_abs=a.margin_abs)
    for o in outcomes:
        print(o.message)
    n_fail = sum(not o.passed for o in outcomes)
    print(f"{len(outcomes) - n_fail} of {len(outcomes)} gates hold" + (f"; {n_fail} FAILED" if n_fail else ""))
    if a.junit:
        Path(a.junit).write_text(junit_xml(outcomes))
    return 1 if n_fail else 0
