"""``scenegen`` command line: validate, render, info, verify.

Bad input (spec errors, bad options, unusable output folders) prints one clear message and exits
with code 2, without a traceback.

Each command imports what it needs when it runs (the renderer, the dataset codecs, the exports
pull in Mitsuba, OpenCV, OpenEXR, trimesh, scipy): ``scenegen --help`` imports nothing but the
standard library, and ``validate`` no more than the spec parser (docs/performance.md).
"""
from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

from scenegen.errors import SpecError

EXIT_BAD_INPUT = 2
#: ``--variant`` choices: scenegen.spec.model.RENDER_VARIANTS (equal, tests/scenegen/test_cli.py)
RENDER_VARIANTS = ("auto", "llvm_ad_rgb", "cuda_ad_rgb", "scalar_rgb")
#: ``export --format`` choices: scenegen.export.FORMATS (equal, tests/scenegen/test_cli.py)
EXPORT_FORMATS = ("colmap", "nerf", "kitti-stereo", "middlebury", "opencv", "tum", "tapvid", "preview", "kitti-flow")


def _err(msg: str) -> int:
    print(f"scenegen: error: {msg}", file=sys.stderr)
    return EXIT_BAD_INPUT


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's own exit code is 2 already; keep its message short
        self.print_usage(sys.stderr)
        sys.exit(_err(message))


def cmd_validate(args) -> int:
    from scenegen.spec import load_spec, resolve_views  # the command's implementation, on use

    spec = load_spec(args.spec)
    views = resolve_views(spec)
    for name, cam in spec.cameras.items():
        cam.to_camera()  # impossible cameras raise here
    for w in spec.warnings:
        print(f"warning: {w}", file=sys.stderr)
    print(f"{args.spec}: OK: {len(spec.objects)} objects, {len(spec.lights)} lights, "
          f"{len(spec.cameras)} cameras, {len(views)} views")
    return 0


def cmd_render(args) -> int:
    from scenegen.pipeline.batch import render_many  # the command's implementation, on use
    from scenegen.pipeline.run import render_spec  # the command's implementation, on use

    many = args.variants is not None or args.workers is not None or args.scheduler is not None
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        kw = dict(frames=args.frames, spp=args.spp, seed=args.seed, variant=args.variant,
                  resume=args.resume, progress=not args.quiet)
        if many:  # variants and/or Dask workers (scenegen/batch.py)
            summaries = render_many(args.spec, args.output, variants=args.variants,
                                    workers=args.workers, scheduler=args.scheduler, **kw)
        else:
            summaries = [render_spec(args.spec, args.output, **kw)]
    for s in summaries:
        _print_summary(s)
    return 0


def _print_summary(s) -> None:
    per = s.seconds / max(s.views_rendered, 1)
    print(f"wrote {s.out_dir}: {s.views_rendered} views rendered, {s.views_skipped} already complete, "
          f"{s.seconds:.1f} s ({per:.2f} s/view), variant {s.settings.variant}, "
          f"spp {s.settings.spp}" + (f" (sampler takes {s.settings.spp_effective})"
                                     if s.settings.spp_effective != s.settings.spp else ""))
    print(f"  images: {s.out_dir / 'images'}   truth: {s.out_dir / 'truth'}   cameras: {s.out_dir / 'cameras.json'}")


def cmd_info(args) -> int:
    from scenegen.dataset import Dataset  # the command's implementation, on use

    d = Dataset(args.dataset)
    m = d.manifest
    print(f"{args.dataset}: {m['format']} v{m['format_version']}, variant {m['variant']}, seed {m['seed']}")
    print(f"  views: {len(d.views)} complete of {len(d.all_views)}; files: {len(m['files'])}")
    for v in d.views[: args.limit]:
        cam, pose = d.camera(v)
        c = pose.inverse().t
        print(f"  {v}: {cam.model} {cam.width}x{cam.height} fx={cam.fx:.2f} fy={cam.fy:.2f} "
              f"centre=({c[0]:.3f}, {c[1]:.3f}, {c[2]:.3f}) m")
    if len(d.views) > args.limit:
        print(f"  ... {len(d.views) - args.limit} more")
    return 0


def cmd_export(args) -> int:
    from scenegen.export import export  # the command's implementation, on use

    s = export(args.dataset, args.format, args.output)
    extra = ", ".join(f"{k} {v}" for k, v in s.items() if k not in ("dest", "files"))
    print(f"exported {args.dataset} as {args.format} to {s['dest']}: {s['files']} files" + (f" ({extra})" if extra else ""))
    return 0


def cmd_verify(args) -> int:
    from scenegen.dataset import verify  # the command's implementation, on use

    r = verify(args.dataset)
    if args.json:
        print(json.dumps(r.__dict__, indent=2, default=list))
    else:
        print(r.summary())
    return 0 if r.ok else 1


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="scenegen", description="Render scene specs into datasets with exact truth.")
    sub = p.add_subparsers(dest="cmd", required=True, parser_class=_Parser)
    v = sub.add_parser("validate", help="check a scene spec")
    v.add_argument("spec", type=Path)
    v.set_defaults(fn=cmd_validate)
    r = sub.add_parser("render", help="render a spec into a dataset folder")
    r.add_argument("spec", type=Path)
    r.add_argument("-o", "--output", type=Path, required=True, help="output dataset folder")
    r.add_argument("--frames", help="frame indices to render, e.g. '0-9,12' (default: all)")
    r.add_argument("--spp", type=int, help="samples per pixel (overrides the spec)")
    r.add_argument("--seed", type=int, help="sampler seed (overrides the spec)")
    r.add_argument("--variant", choices=RENDER_VARIANTS)
    r.add_argument("--resume", action="store_true", help="finish an interrupted run in the same folder")
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    r.add_argument("--variants", type=int, metavar="N",
                   help="render variants 0..N-1 of the spec's 'variation:' section into OUT/variant_0000, ...")
    where = r.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N", help="render on a local Dask cluster of N worker processes")
    where.add_argument("--scheduler", metavar="ADDRESS", help="render on an existing Dask cluster, e.g. tcp://host:8786")
    r.set_defaults(fn=cmd_render)
    i = sub.add_parser("info", help="summarise a dataset")
    i.add_argument("dataset", type=Path)
    i.add_argument("--limit", type=int, default=10)
    i.set_defaults(fn=cmd_info)
    f = sub.add_parser("verify", help="re-hash every file of a dataset")
    f.add_argument("dataset", type=Path)
    f.add_argument("--json", action="store_true")
    f.set_defaults(fn=cmd_verify)
    e = sub.add_parser("export", help="export a dataset to colmap, nerf, kitti-stereo, middlebury, opencv, tum, tapvid, preview or kitti-flow")
    e.add_argument("dataset", type=Path)
    e.add_argument("--format", required=True, choices=EXPORT_FORMATS)
    e.add_argument("-o", "--output", type=Path, help="destination folder (default: <dataset>.<format>)")
    e.set_defaults(fn=cmd_export)
    return p


def _bad_input_errors() -> tuple[type, ...]:
    """The exceptions that mean bad input. The dataset's and the renderer's are taken from
    sys.modules: an error of a module this run never imported cannot have been raised."""
    found = [ValueError, FileNotFoundError]
    for module, name in (("scenegen.dataset.errors", "DatasetError"), ("scenegen.render.backend", "BackendError")):
        if module in sys.modules:
            found.append(getattr(sys.modules[module], name))
    return tuple(found)


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.fn(args)
    except SpecError as e:
        return _err(str(e))
    except Exception as e:  # bad input is told apart here; anything else propagates
        if isinstance(e, _bad_input_errors()):
            return _err(str(e))
        if isinstance(e, BrokenPipeError):  # output piped into e.g. `head`
            return 0
        raise
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
