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
from recon_eval.runners.declared import external_method, load_methods
from recon_eval.runners.external import KINDS, PIXELS, TIMEOUT_S

EXIT_GATE_FAILED = 1


def _declared_arguments(p) -> None:
    p.add_argument("--methods-file", metavar="METHODS.yaml",
                   help="your own methods: command lines with an output kind (docs/ci.md, 'Your own estimator')")


def run_arguments(p) -> None:
    p.add_argument("method", help="method name (recon-eval run --list shows them); with --command omit it",
                   nargs="?")
    p.add_argument("dataset", nargs="?", help="scenegen dataset folder")
    p.add_argument("-o", "--out", help="results folder (raw outputs + result.json)")
    p.add_argument("--list", action="store_true", help="list the methods (and the deliberately broken ones) and exit")
    p.add_argument("--quiet", action="store_true")
    _declared_arguments(p)
    p.add_argument("--command", metavar="CMD", dest="external_command", help="run your own estimator: a command line with placeholders "
                                                    "({images} {out} ..., per --kind; no shell)")
    p.add_argument("--kind", choices=list(KINDS), help="--command: what it writes, and so how it is scored: "
                   + "; ".join(f"{k.name}: {k.contract}" for k in KINDS.values()).replace("%", "%%"))  # argparse formats help
    p.add_argument("--name", default="external", help="--command: the method name in the results (default external)")
    p.add_argument("--timeout", type=float, default=TIMEOUT_S, metavar="S",
                   help=f"--command: seconds per invocation (default {TIMEOUT_S:g})")
    p.add_argument("--pixels", choices=list(PIXELS),
                   help="--command --kind fmatrix on images: the pixels F is for (default distorted: the raw images)")


def _declared(a) -> dict:
    return load_methods(a.methods_file) if a.methods_file else {}


def run(a) -> int:
    declared = _declared(a)
    if a.list:
        for m in METHODS.values():
            print(f"{m.name:28s} {m.description}")
        for m in FAULTS.values():
            print(f"{m.name:28s} [fault] {m.description}")
        for m in declared.values():
            print(f"{m.name:28s} [declared] {m.description}")
        return 0
    name = a.method
    if a.external_command:
        if not a.kind:
            raise InputError("--command needs --kind (" + ", ".join(KINDS) + ")")
        if a.dataset and a.method:
            raise InputError("with --command give DATASET -o RESULTS only (the method is the command; --name names it)")
        a.dataset, name = a.dataset or a.method, a.name
        declared = {**declared, name: external_method(name, a.kind, a.external_command, timeout_s=a.timeout, pixels=a.pixels)}
    elif a.kind or a.pixels:
        raise InputError("--kind and --pixels go with --command")
    if not (name and a.dataset and a.out):
        raise InputError("run needs METHOD DATASET -o RESULTS (or --command CMD --kind KIND DATASET -o RESULTS, or "
                         "--list)")
    doc = run_method(name, a.dataset, a.out, declared=declared)
    if not a.quiet:
        from rich.console import Console  # heavy; only the printed table needs it
        from rich.table import Table  # (rich, as above)

        t = Table(title=f"recon-eval run {name} ({doc['inputs']['scene']})")
        t.add_column("metric")
        t.add_column("value")
        for k, v in doc["metrics"].items():
            t.add_row(k, f"{v:.6g}" if isinstance(v, float) else str(v))
        Console().print(t)
    return 0


def leaderboard_arguments(p) -> None:
    p.add_argument("--datasets", nargs="+", required=True, help="scenegen dataset folders")
    p.add_argument("--methods", nargs="+", required=True, help="method names (built-in or of --methods-file)")
    p.add_argument("-o", "--out", required=True, help="output folder")
    _declared_arguments(p)
    p.add_argument("--gates", metavar="GATES.yaml", help="check the runs against a gate file: the outcomes are "
                                                         "printed and coloured in leaderboard.html; exit 1 if one fails")


def leaderboard(a) -> int:
    """-q: nothing printed but errors and the gates that fail (the files are written)."""
    say = (lambda _line: None) if a.quiet else print
    gates = load_gates(a.gates) if a.gates else None  # a bad gate file fails before anything runs
    doc = run_leaderboard(a.datasets, a.methods, a.out, declared=_declared(a), log=say)
    outcomes = []
    if gates:
        outcomes = evaluate(gates, [(f"leaderboard.json#runs[{k}]", r) for k, r in enumerate(doc["runs"])])
        for o in outcomes:
            (print if not o.passed else say)(o.message)
    for p in write_all(doc, a.out, outcomes):
        say(f"wrote {p}")
    return EXIT_GATE_FAILED if any(not o.passed for o in outcomes) else 0


def gate_arguments(p) -> None:
    p.add_argument("gates", help="gate file (YAML, docs/ci.md)")
    p.add_argument("results", nargs="+", help="result JSON files: any scoring command's --json, 'recon-eval run' "
                                              "result.json, leaderboard.json")
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
