"""Scored commands: the ones that write recon_eval's versioned report. Each is a function
``score(args) -> (inputs, results, figures)`` (provenance, metric name -> result dataclass, and a
function returning the HTML :class:`recon_eval.report.html.Figure` list, called only for
``--html``); :func:`scored` makes it a command that prints the table and writes ``--json`` and
``--html``. ``--method`` and ``--scene`` label the result for ``recon-eval gate`` and the
leaderboard (``inputs.method``, ``inputs.scene``); the scene defaults to the dataset's own when
the truth is a scenegen dataset."""
from __future__ import annotations

from typing import Callable

from recon_eval.cli.registry import Impl
from recon_eval.errors import InputError
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from recon_eval.report.document import document, print_table, to_jsonable, write_json_atomic
from recon_eval.report.html import render_html, write_html_atomic


def no_figures() -> list:
    return []


def scored(arguments: Callable, score: Callable, headline: Callable | None = None) -> Impl:
    """The :class:`Impl` of a scored command: ``--json``, ``--html`` and ``--quiet``, then the
    command's own ``arguments(parser)``; running it calls ``score(args)`` and reports.
    ``headline(args, results) -> {name: number}`` gives the JSON's ``metrics``: the headline numbers
    under the names ``recon-eval run`` gives the same numbers (docs/ci.md, "Metric paths"), so one
    gate file gates a method run and the same method scored by hand."""

    def add(p) -> None:
        p.add_argument("--json", metavar="OUT", help="write the JSON report here (atomically)")
        p.add_argument("--html", metavar="OUT",
                       help="write a self-contained HTML report with figures (needs matplotlib)")
        p.add_argument("--quiet", action="store_true", help="do not print the table")
        p.add_argument("--method", metavar="NAME", help="the method name written into the JSON (inputs.method), "
                                                        "for gates and leaderboards")
        p.add_argument("--scene", metavar="NAME", help="the scene name written into the JSON (inputs.scene; "
                                                       "default: the dataset's scene when the truth is a dataset)")
        arguments(p)

    def run(a) -> int:
        inputs, results, figures = score(a)
        inputs = label_inputs(inputs, a)
        metrics = headline(a, results) if headline is not None else None
        if not a.quiet:
            print_table(f"recon-eval {a.command}", results)
        if a.json:
            doc = document(a.command, inputs, results)
            if metrics is not None:
                doc["metrics"] = to_jsonable(metrics)
            write_json_atomic(a.json, doc)
        if a.html:
            try:
                import matplotlib  # noqa: F401  (optional: only the HTML report's figures need it)
            except ImportError:
                raise InputError("--html needs matplotlib (pip install matplotlib)") from None
            write_html_atomic(a.html, render_html(a.command, inputs, results, figures(), metrics=metrics))
        return 0

    return Impl(add, run)


#: Arguments of scored commands that may name the truth dataset (its scene labels the result).
DATASET_ARGUMENTS = ("dataset", "gt")


def label_inputs(inputs: dict, a) -> dict:
    """``inputs`` with ``method`` and ``scene`` set from ``--method``/``--scene``, the scene else
    from the truth dataset (the first of :data:`DATASET_ARGUMENTS` that is one)."""
    out = dict(inputs)
    if getattr(a, "method", None):
        out["method"] = a.method
    scene = getattr(a, "scene", None)
    for name in DATASET_ARGUMENTS:
        if scene:
            break
        value = getattr(a, name, None)
        if isinstance(value, str) and is_dataset(value):
            scene = read_dataset(value).scene_name
    if scene:
        out["scene"] = scene
    return out
