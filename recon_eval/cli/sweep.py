"""``recon-eval sweep``: estimators of one kind (``--kind``: fundamental matrices by default, or
homographies, essential matrices, PnP, triangulation; :data:`recon_eval.sweep.kinds.KINDS`) over
Gaussian noise and outlier fractions drawn from a dataset's exact truth (docs/fmatrix_survey.md,
docs/sweeps.md). Writes ``OUT/sweep.json`` (the
versioned result document, ``command: "sweep"``), ``OUT/report.html`` (the cells and the plots of
error against noise and against outliers per method family) and, with ``--markdown``, the
tables. Exit 0, or 2 on bad input."""
from __future__ import annotations

import sys
from pathlib import Path

from recon_eval.cli.registry import Impl
from recon_eval.errors import InputError
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.report.document import document, write_json_atomic
from recon_eval.report.html import render_html, write_html_atomic
from recon_eval.report.sweep_report import breakdown_table, figures, markdown
from recon_eval.runners.common import RunOutput
from recon_eval.runners.declared import external_method, load_methods
from recon_eval.runners.external import TIMEOUT_S
from recon_eval.sweep.kinds import KINDS
from recon_eval.sweep.run import SweepConfig, run_sweep
from scenegen.dataset.files import atomic_write_bytes

#: Truth correspondences the trials are drawn from (seeded sample of the pair's dense truth).
TRUTH_POOL = 20000


def arguments(p) -> None:
    p.add_argument("dataset", help="scenegen dataset folder")
    p.add_argument("-o", "--out", required=True, help="output folder (sweep.json, report.html)")
    p.add_argument("--kind", choices=list(KINDS), default="f",
                   help="what is estimated: f (default), h (a planar scene's pair), e, pnp (one view), triangulation")
    p.add_argument("--views", nargs="+", metavar="VIEW",
                   help="the pair VIEW1 VIEW2 (default: the first cross-view pair); --kind pnp: one view (default: "
                        "the first)")
    p.add_argument("--object", metavar="NAME", dest="object_name",
                   help="--kind h, e, pnp, triangulation: only the truth points on this spec object (--kind h: a "
                        "planar object of a larger scene)")
    p.add_argument("--sigmas", type=float, nargs="+", default=[0.0, 0.5, 1.0, 2.0], metavar="PX",
                   help="Gaussian noise per coordinate, px (default 0 0.5 1 2)")
    p.add_argument("--outliers", type=float, nargs="+", default=[0.0, 0.1, 0.2, 0.3, 0.4, 0.5], metavar="F",
                   help="outlier fractions in [0, 1) (default 0 0.1 0.2 0.3 0.4 0.5)")
    p.add_argument("--trials", type=int, default=5, help="trials per cell (default 5)")
    p.add_argument("--points", type=int, default=200, help="correspondences per trial (default 200)")
    p.add_argument("--seed", type=int, default=0, help="the seed of every trial and method (default 0)")
    p.add_argument("--breakdown", "--breakdown-px", type=float, dest="breakdown", metavar="E",
                   help="median trial error (the kind's unit) above which a method has broken down (default: f, h, "
                        "pnp 2 px; e 5 deg; triangulation 0.05 m)")
    p.add_argument("--methods", nargs="+", metavar="NAME",
                   help="--kind f: survey-f-<name>, opencv-f-<flag>, or your methods (default: the survey's "
                        "nineteen); other kinds: their OpenCV methods (default: all; docs/sweeps.md)")
    p.add_argument("--methods-file", metavar="METHODS.yaml", help="your methods (kind fmatrix with {matches})")
    p.add_argument("--command", metavar="CMD", dest="external_command",
                   help="your F method: a command line with {matches} (n x 4 .npy) and {out} (F, 3x3 text)")
    p.add_argument("--name", default="external", help="--command: its name (default external)")
    p.add_argument("--timeout", type=float, default=TIMEOUT_S, metavar="S", help="--command: seconds per trial")
    p.add_argument("--markdown", metavar="OUT.md", help="also write the tables as Markdown")
    p.add_argument("--quiet", action="store_true", help="print no progress and no table")


def _views(a, ds, kind) -> tuple:
    if a.views:
        if len(a.views) != kind.n_views:
            raise InputError(f"--views: --kind {kind.name} takes {kind.n_views} view(s), got {len(a.views)}")
        return tuple(a.views)
    if kind.n_views == 1:
        return (ds.views[0],)
    pairs = ds.crossview_pairs()
    if not pairs:
        raise InputError(f"{ds.root}: no cross-view pairs: give --views VIEW1 VIEW2")
    return tuple(pairs[0])


def run(a) -> int:
    kind = KINDS[a.kind]
    breakdown = kind.default_breakdown if a.breakdown is None else a.breakdown
    config = SweepConfig(tuple(a.sigmas), tuple(a.outliers), a.trials, a.points, a.seed, breakdown, kind.name).check()
    declared = load_methods(a.methods_file) if a.methods_file else {}
    names = list(a.methods or kind.default_methods())
    if a.external_command:
        declared = {**declared, a.name: external_method(a.name, "fmatrix", a.external_command, timeout_s=a.timeout)}
        names.append(a.name)
    notes = RunOutput()
    methods = kind.resolve(names, declared, notes)
    ds = read_dataset(a.dataset)
    views = _views(a, ds, kind)
    truth = kind.truth(ds, views, TRUTH_POOL, a.object_name)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    say = None if a.quiet else (lambda s: print(f"recon-eval sweep: {s}", file=sys.stderr))
    results = run_sweep(truth, methods, config, out / "work", progress=say)
    results["notes"] = notes.notes
    inputs = {"dataset": str(a.dataset), "scene": ds.scene_name, "kind": kind.name, "views": list(views),
              "pixels": "undistorted", "truth": kind.notes(truth), "measure": kind.measure,
              "methods": {m.name: {"family": m.family, "description": m.description, "params": m.params}
                          for m in methods}}
    doc = document("sweep", inputs, results)
    write_json_atomic(out / "sweep.json", doc)
    html_results = {f"{c['method']}.sigma_{c['sigma_px']:g}.outliers_{c['outlier_fraction']:g}":
                    {k: v for k, v in c.items() if k not in ("trials", "method", "family")}
                    for c in doc["results"]["cells"]}
    write_html_atomic(out / "report.html", render_html("sweep", inputs, html_results, figures(doc["results"])))
    if a.markdown:
        atomic_write_bytes(a.markdown, (markdown(doc["results"]) + "\n").encode("utf-8"))
    if not a.quiet:
        print(breakdown_table(doc["results"]))
        print(f"wrote {out / 'sweep.json'} and {out / 'report.html'}")
    return 0


COMMANDS = {"sweep": Impl(arguments, run)}
