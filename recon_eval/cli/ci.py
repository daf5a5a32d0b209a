"""The ``run``, ``leaderboard`` and ``gate`` subcommands of ``recon-eval`` (registered in
:mod:`recon_eval.cli.registry`; docs/ci.md). Exit codes: 0 ok / all gates hold, 1 a gate failed,
2 bad input."""
from __future__ import annotations

from pathlib import Path

from recon_eval.ci.gates import compare_baseline, evaluate, junit_xml, load_gates, load_results
from recon_eval.ci.leaderboard import run_leaderboard, write_all
from recon_eval.cli.registry import Impl
from recon_eval.errors import InputError
from recon_eval.runners import FAULTS, METHODS, run_method

EXIT_GATE_FAILED = 1


def run_arguments(p) -> None:
    p.add_argument("method", help="method name (recon-eval run --list shows them)", nargs="?")
    p.add_argument("dataset", nargs="?", help="scenegen dataset folder")
    p.add_argument("-o", "--out", help="results folder (raw outputs + result.json)")
    p.add_argument("--list", action="store_true", help="list the methods (and the deliberately broken ones) and exit")
    p.add_argument("--quiet", action="store_true")


def run(a) -> int:
    if a.list:
        for m in METHODS.values():
            print(f"{m.name:28s} {m.description}")
        for m in FAULTS.values():
            print(f"{m.name:28s} [fault] {m.description}")
        return 0
    if not (a.method and a.dataset and a.out):
        raise InputError("run needs METHOD DATASET -o RESULTS (or --list)")
    doc = run_method(a.method, a.dataset, a.out)
    if not a.quiet:
        from rich.console import Console  # heavy; only the printed table needs it
        from rich.table import Table  # (rich, as above)

        t = Table(title=f"recon-eval run {a.method} ({doc['inputs']['scene']})")
        t.add_column("metric")
        t.add_column("value")
        for k, v in doc["metrics"].items():
            t.add_row(k, f"{v:.6g}" if isinstance(v, float) else str(v))
        Console().print(t)
    return 0


def leaderboard_arguments(p) -> None:
    p.add_argument("--datasets", nargs="+", required=True, help="scenegen dataset folders")
    p.add_argument("--methods", nargs="+", required=True, help="method names")
    p.add_argument("-o", "--out", required=True, help="output folder")


def leaderboard(a) -> int:
    doc = run_leaderboard(a.datasets, a.methods, a.out)
    for p in write_all(doc, a.out):
        print(f"wrote {p}")
    return 0


def gate_arguments(p) -> None:
    p.add_argument("gates", help="gate file (YAML, docs/ci.md)")
    p.add_argument("results", nargs="+", help="result.json of 'recon-eval run' or leaderboard.json files")
    p.add_argument("--junit", metavar="OUT.xml", help="write a JUnit XML report")
    p.add_argument("--baseline", action="append", metavar="STORED.json",
                   help="stored results: also fail when a gated metric worsens by more than the margin")
    p.add_argument("--margin", type=float, default=0.10, help="baseline: allowed relative worsening (default 0.10)")
    p.add_argument("--margin-abs", type=float, default=0.0, help="baseline: allowed absolute worsening (default 0)")


def gate(a) -> int:
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
    return EXIT_GATE_FAILED if n_fail else 0


COMMANDS = {"run": Impl(run_arguments, run), "leaderboard": Impl(leaderboard_arguments, leaderboard),
            "gate": Impl(gate_arguments, gate)}
