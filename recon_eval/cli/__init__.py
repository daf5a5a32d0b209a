"""``recon-eval``: one subcommand per metric family (the table: :mod:`recon_eval.cli.registry`).
A scored command (:mod:`recon_eval.cli.scored`) prints a table; ``--json OUT`` writes the
versioned JSON report (see :mod:`recon_eval.report.document`); ``--html OUT`` a self-contained
HTML report with figures (:mod:`recon_eval.report.html`, needs matplotlib). Bad input -> a
message naming the file and what was expected, exit code 2, no traceback; ``gate``: exit 1 when
a gate fails.

Wherever it makes sense the truth may be one of our dataset folders (docs/dataset_format.md):
poses from cameras.json, depth and disparity from the truth EXRs, the GT surface from
scene/meshes, held-out truth points for calibration and PnP, dense visible correspondences and
the truth F for fundamental matrices.

Examples::

    recon-eval cloud REC.ply GT.ply --tau 0.01
    recon-eval cloud REC.ply DATASET_DIR --tau 0.01                   # GT = the dataset's meshes
    recon-eval poses EST_MODEL_DIR GT_MODEL_DIR --alignment sim3     # COLMAP models (bin or txt)
    recon-eval poses EST_MODEL_DIR DATASET_DIR                       # matched by image name = view
    recon-eval poses transforms.json DATASET_DIR                     # NeRF / instant-ngp
    recon-eval poses est_kitti.txt DATASET_DIR --camera cam0         # KITTI: line i = i-th view
    recon-eval poses est_tum.txt gt_tum.txt                          # TUM trajectories
    recon-eval disparity EST.png GT.png --benchmark kitti
    recon-eval disparity EST.pfm DATASET_DIR --view left_000 --benchmark middlebury
    recon-eval depth EST.npy GT.npy --alignment median
    recon-eval depth EST_DIR DATASET_DIR                             # EST_DIR/<view>.npy|.pfm|.exr
    recon-eval fmatrix F_est.txt --matches matches.npy --f-gt F_gt.txt --size 640 480
    recon-eval fmatrix F_est.txt --dataset DATASET_DIR --views cam0_000 cam1_000
    recon-eval homography H_est.txt H_gt.txt --size 640 480
    recon-eval calibration est.yaml DATASET_DIR --view cam0_000
    recon-eval pnp pose.json DATASET_DIR --view cam0_000
    recon-eval features RESULT DATASET                               # docs/features.md
    recon-eval dlt P.txt DATASET --view obj_0000                     # docs/metrics.md
    recon-eval run opencv-f-ransac DATASET -o RESULTS                # docs/ci.md

Global options, before or after the command: ``--version``; ``-q/--quiet`` (no progress lines,
no table: the JSON/HTML reports and the exit code only); ``-v/--verbose`` (also the command's
time, and the traceback of an error).
"""
from __future__ import annotations

import argparse
import importlib
import sys
import time
import traceback

from recon_eval import __version__
from recon_eval.cli.common import configure_progress
from recon_eval.cli.registry import BY_NAME, COMMANDS
from recon_eval.errors import InputError
from scenegen.errors import os_error_message

EXIT_BAD_INPUT = 2


def _family(command: str):
    """The family module of ``command`` (imported on first use: it loads the heavy readers)."""
    return importlib.import_module(f"recon_eval.cli.{BY_NAME[command].family}")


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line usage error (exit 2, as argparse's own) pointing at ``--help``."""

    def error(self, message):
        print(f"{self.prog}: error: {message} (see {self.prog} --help)", file=sys.stderr)
        sys.exit(EXIT_BAD_INPUT)


def build_parser(argv=None, *, full: bool = False) -> argparse.ArgumentParser:
    """The ``recon-eval`` parser. Every command is listed; the arguments are added for the command
    named in ``argv`` (its family module is imported), or for every command with ``full``."""
    ap = _Parser(prog="recon-eval", description="Score 3D-vision results against exact ground truth.")
    ap.add_argument("--version", action="version", version=f"recon-eval {__version__}")
    global_options(ap, top=True)
    sub = ap.add_subparsers(dest="command", required=True, metavar="COMMAND")
    chosen = next((t for t in (argv or []) if not t.startswith("-")), None)
    for c in COMMANDS:
        p = sub.add_parser(c.name, help=c.help, description=c.description or c.help)
        if full or c.name == chosen:
            _family(c.name).COMMANDS[c.name].arguments(p)
            global_options(p, top=False)
    return ap


def global_options(p: argparse.ArgumentParser, *, top: bool) -> None:
    """-q/--quiet and -v/--verbose, on the top parser and again after the command (SUPPRESS: not
    resetting what came before); a command's own ``--quiet`` (no table) is the same switch."""
    if top:  # own names: a command's --quiet default (False) would overwrite the top's value
        p.add_argument("-q", "--quiet", dest="quiet_all", action="store_true",
                       help="no progress lines and no table (reports and exit code only)")
        p.add_argument("-v", "--verbose", dest="verbose_all", action="store_true",
                       help="also the command's time and the traceback of an error")
        return
    d = {"default": argparse.SUPPRESS}
    have = p._option_string_actions  # noqa: SLF001 (argparse has no public lookup)
    if "--quiet" in have and not have["--quiet"].help:  # a command's own --quiet, undocumented
        have["--quiet"].help = "print nothing but errors (the result files are still written)"
    quiet = [o for o in ("-q", "--quiet") if o not in have]
    if quiet:
        p.add_argument(*quiet, dest="quiet", action="store_true",
                       help="no progress lines and no table (reports and exit code only)", **d)
    verbose = [o for o in ("-v", "--verbose") if o not in have]
    if verbose:
        p.add_argument(*verbose, dest="verbose", action="store_true",
                       help="also the command's time and the traceback of an error", **d)


def parse_args(argv) -> argparse.Namespace:
    """The parsed command line; ``quiet`` and ``verbose`` true when given before or after the
    command (argparse itself exits with code 2 on bad usage)."""
    args = build_parser(argv).parse_args(argv)
    args.quiet = bool(getattr(args, "quiet", False) or args.quiet_all)
    args.verbose = bool(getattr(args, "verbose", False) or args.verbose_all)
    return args


def main(argv=None) -> int:
    """Run one command; its exit code: 0 ok, 1 a gate failed, 2 bad input (no traceback)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    bad = next((a for a in argv if "\x00" in str(a)), None)
    if bad is not None:  # no path, name or option can hold one
        print(f"recon-eval: error: the argument {str(bad)!r} contains a NUL byte", file=sys.stderr)
        return EXIT_BAD_INPUT
    args = parse_args(argv)  # argparse itself exits with code 2 on bad usage
    configure_progress(enabled=not args.quiet, every_s=0.5 if args.verbose else 2.0)
    t0 = time.perf_counter()
    try:
        code = _family(args.command).COMMANDS[args.command].run(args)
        if args.verbose:
            print(f"recon-eval {args.command}: {time.perf_counter() - t0:.2f} s", file=sys.stderr)
        return code
    except InputError as exc:
        if args.verbose:
            traceback.print_exc()
        print(f"recon-eval: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:  # unreadable input or unwritable output
        if args.verbose:
            traceback.print_exc()
        print(f"recon-eval: error: {os_error_message(exc)}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
