"""``scenegen`` command line: validate, render, preview, info, verify, export, gallery, examples.

Bad input (spec errors, bad options, unusable output folders) prints one clear message and exits
with code 2, without a traceback (``-v`` adds the traceback). ``-q`` silences progress and
remarks, ``-v`` adds timings; both may come before or after the command.

Each command imports what it needs when it runs (the renderer, the dataset codecs, the exports
pull in Mitsuba, OpenCV, OpenEXR, trimesh, scipy): ``scenegen --help`` imports nothing but the
standard library, and ``validate`` no more than the spec parser (docs/performance.md).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
import warnings
from pathlib import Path

from scenegen import __version__
from scenegen.errors import SpecError, os_error_message

EXIT_BAD_INPUT = 2
#: ``--variant`` choices: scenegen.spec.model.RENDER_VARIANTS (equal, tests/scenegen/test_cli.py)
RENDER_VARIANTS = ("auto", "llvm_ad_rgb", "cuda_ad_rgb", "scalar_rgb")
#: ``export --format`` choices: scenegen.export.FORMATS (equal, tests/scenegen/test_cli.py)
EXPORT_FORMATS = ("colmap", "gaussian-splatting", "nerf", "kitti-stereo", "middlebury", "opencv", "tum", "tapvid",
                  "tracks-video", "kitti-flow", "kitti-sceneflow", "sintel", "euroc",
                  "kitti-velodyne", "nuscenes-lidar", "lidar-pcd", "lidar-ply", "kitti-odometry", "tof", "bop", "coco")
#: Verbosity: -q 0, default 1, -v 2.
QUIET, NORMAL, VERBOSE = 0, 1, 2


def _err(msg: str, args=None) -> int:
    if args is not None and getattr(args, "verbosity", NORMAL) >= VERBOSE:
        traceback.print_exc()
    print(f"scenegen: error: {msg}", file=sys.stderr)
    return EXIT_BAD_INPUT


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's own exit code is 2 already; keep its message short
        self.print_usage(sys.stderr)
        sys.exit(_err(message))


def cmd_validate(args) -> int:
    from scenegen.spec import load_spec, resolve_views  # the command's implementation, on use
    from scenegen.spec.model import effective_spp  # the command's implementation, on use

    spec = load_spec(args.spec)
    views = resolve_views(spec)
    if any(o.geometry.kind == "mesh" or getattr(getattr(o.material, "texture", None), "kind", "") == "image"
           for o in spec.objects) or any(light.type == "envmap" for light in spec.lights):
        # files render would read: read them as it does (trimesh, cv2, OpenEXR only then)
        from scenegen.spec.assets_check import check_assets  # the command's implementation, on use
        check_assets(spec)  # errors at the spec's file:line
    for name, cam in spec.cameras.items():
        cam.to_camera()  # impossible cameras raise here
    if args.verbosity > QUIET:
        for w in spec.warnings:
            print(f"warning: {w}", file=sys.stderr)
    rs = spec.render
    n = effective_spp(rs.sampler, rs.spp)
    print(f"{args.spec}: OK: {len(spec.objects)} objects, {len(spec.lights)} lights, "
          f"{len(spec.cameras)} cameras, {len(views)} views, spp {rs.spp}"
          + (f" (the {rs.sampler} takes {n})" if n != rs.spp else ""))
    return 0


def cmd_render(args) -> int:
    from scenegen.pipeline.batch import render_many  # the command's implementation, on use
    from scenegen.pipeline.run import render_spec  # the command's implementation, on use
    from scenegen.render.backend import renderer_log  # the command's implementation, on use

    many = args.variants is not None or args.workers is not None or args.scheduler is not None
    with warnings.catch_warnings(), renderer_log(args.verbosity > QUIET):
        warnings.simplefilter("always")
        kw = dict(frames=args.frames, spp=args.spp, seed=args.seed, variant=args.variant,
                  resume=args.resume, progress=args.verbosity > QUIET and not args.no_progress,
                  show_warnings=args.verbosity > QUIET)
        if many:  # variants and/or Dask workers (scenegen/batch.py)
            summaries = render_many(args.spec, args.output, variants=args.variants,
                                    workers=args.workers, scheduler=args.scheduler, **kw)
        else:  # a failed run removes the folder only if it created it (DatasetWriter.discard)
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


def _truth_kinds(d) -> dict:
    """Which truth the dataset holds: the per-view maps (of its first view), and the kinds of the
    cross-view and sequence stages (their folders; a sequence's per-object poses)."""
    def under(top: str) -> list[str]:
        kinds = {p.split("/")[1] for p in d.manifest["files"] if p.startswith(top + "/") and p.count("/") > 1}
        if top == "sequence" and "sequence/objects.json" in d.manifest["files"]:
            kinds.add("object poses")
        return sorted(kinds)
    return {"view": sorted(d.truth(d.views[0])) if d.views else [], "crossview": under("crossview"),
            "sequence": under("sequence")}


def _sequence_text(q: dict) -> str:
    t = q["timestamps_s"]
    clock = f"{q['frames']} frames at {q['fps']:g} fps" if q.get("fps") else f"{len(t)} frames"
    return (f"{clock}, t = {t[0]:g} .. {t[-1]:g} s; flow steps {', '.join(map(str, q['flow_steps']))}"
            + (f"; {q['tracks']['count']} point tracks" if q.get("tracks") else ""))


def info_document(d) -> dict:
    """What ``info --json`` prints: the manifest's identity and every complete view's camera."""
    m = d.manifest
    views = {}
    for v in d.views:
        cam, pose = d.camera(v)
        info = d.view_info(v)
        views[v] = {"camera_name": info.get("camera_name"), "rig": info.get("rig"),
                    "frame_index": info.get("frame_index"), "camera": cam.to_dict(),
                    "cam_from_world": pose.to_dict(), "centre_m": pose.inverse().t.tolist()}
    return {"dataset": str(d.root), "scene": d.scene_name, "format": m["format"], "format_version": m["format_version"],
            "variant": m["variant"], "seed": m["seed"], "views_complete": len(d.views),
            "views_total": len(d.all_views), "files": len(m["files"]),
            "sequence": (d.spec or {}).get("sequence"), "truth": _truth_kinds(d),
            "crossview": d.crossview.index is not None, "views": views}


def cmd_info(args) -> int:
    from scenegen.dataset import Dataset  # the command's implementation, on use

    d = Dataset(args.dataset)
    if args.json:
        print(json.dumps(info_document(d), indent=2))
        return 0
    m = d.manifest
    print(f"{args.dataset}: scene {d.scene_name!r}, {m['format']} v{m['format_version']}, variant {m['variant']}, "
          f"seed {m['seed']}")
    print(f"  views: {len(d.views)} complete of {len(d.all_views)}; files: {len(m['files'])}")
    if (q := (d.spec or {}).get("sequence")) is not None:
        print(f"  sequence: {_sequence_text(q)}")
    kinds = _truth_kinds(d)
    print(f"  truth per view: {', '.join(kinds['view']) or 'none'}")
    print(f"  cross-view truth: {', '.join(kinds['crossview']) or 'none'}")
    if kinds["sequence"]:
        print(f"  sequence truth: {', '.join(kinds['sequence'])}")
    for v in d.views[: args.limit]:
        cam, pose = d.camera(v)
        c = pose.inverse().t
        print(f"  {v}: {cam.model} {cam.width}x{cam.height} fx={cam.fx:.2f} fy={cam.fy:.2f} "
              f"centre=({c[0]:.3f}, {c[1]:.3f}, {c[2]:.3f}) m")
    if len(d.views) > args.limit:
        print(f"  ... {len(d.views) - args.limit} more")
    return 0


def _summary_text(v) -> str:
    """A summary value as words, not Python's repr: ``a: x; b: y`` for a mapping, ``a, b`` for a list."""
    if isinstance(v, dict):
        return "; ".join(f"{k}: {_summary_text(x)}" for k, x in v.items())
    if isinstance(v, (list, tuple)):
        return ", ".join(map(str, v))
    return str(v)


def cmd_export(args) -> int:
    from scenegen.export import PROGRESS_UNITS, export  # the command's implementation, on use
    from scenegen.pipeline.progress import line_progress  # the command's implementation, on use

    s = export(args.dataset, args.format, args.output,
               progress=line_progress(f"export {args.format}", PROGRESS_UNITS[args.format],
                                      enabled=args.verbosity > QUIET))
    extra = ", ".join(f"{k} {_summary_text(v)}" for k, v in s.items() if k not in ("dest", "files"))
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


def cmd_preview(args) -> int:
    from scenegen.pipeline.preview import preview  # the command's implementation, on use
    from scenegen.render.backend import renderer_log  # the command's implementation, on use

    with renderer_log(args.verbosity > QUIET):
        r = preview(args.spec, args.output, spp=args.spp, max_width=args.tile_width, variant=args.variant,
                    progress=args.verbosity > QUIET)
    print(f"wrote {r['png']}: {r['views']} views x (image, depth, normals, ids), spp {r['spp']}, "
          f"{r['seconds']:.1f} s")
    return 0


def cmd_gallery(args) -> int:
    from scenegen.export.gallery import gallery  # the command's implementation, on use
    from scenegen.pipeline.progress import line_progress  # the command's implementation, on use

    r = gallery(args.dataset, args.output, max_width=args.tile_width,
                progress=line_progress("gallery", "views", enabled=args.verbosity > QUIET))
    print(f"wrote {r['png']} and {r['html']}: {r['views']} views")
    return 0


def cmd_examples(args) -> int:
    from scenegen.bundled import copy_examples, example_files  # the command's implementation, on use

    if args.copy is not None:
        n = copy_examples(args.copy)
        print(f"copied {n} files into {args.copy} (scenes/, gates/, examples/, baselines/)")
        return 0
    for kind, path in example_files():
        print(f"{kind}\t{path}")
    return 0


def _global_options(p: argparse.ArgumentParser, *, top: bool) -> None:
    """-q / -v, accepted before and after the command (after it, they do not reset what came
    before: SUPPRESS)."""
    d = {} if top else {"default": argparse.SUPPRESS}
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bars or remarks on stderr", **d)
    p.add_argument("-v", "--verbose", action="store_true",
                   help="also timings, and the traceback of an error", **d)


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="scenegen", description="Render scene specs into datasets with exact truth.")
    p.add_argument("--version", action="version", version=f"scenegen {__version__}")
    _global_options(p, top=True)
    sub = p.add_subparsers(dest="cmd", required=True, parser_class=_Parser, metavar="COMMAND")

    def command(name, fn, help_):
        c = sub.add_parser(name, help=help_, description=help_[0].upper() + help_[1:] + ".")
        _global_options(c, top=False)
        c.set_defaults(fn=fn)
        return c

    v = command("validate", cmd_validate, "check a scene spec (parse it, place every view, check every camera)")
    v.add_argument("spec", type=Path, help="the scene spec (YAML, docs/scene_spec.md)")
    r = command("render", cmd_render, "render a spec into a dataset folder")
    r.add_argument("spec", type=Path, help="the scene spec (YAML, docs/scene_spec.md)")
    r.add_argument("-o", "--output", type=Path, required=True, help="output dataset folder (new or empty)")
    r.add_argument("--frames", help="frame indices to render, e.g. '0-9,12' (default: all)")
    r.add_argument("--spp", type=int, help="samples per pixel (overrides the spec)")
    r.add_argument("--seed", type=int, help="sampler seed (overrides the spec)")
    r.add_argument("--variant", choices=RENDER_VARIANTS, help="Mitsuba variant (default: the spec's, 'auto')")
    r.add_argument("--resume", action="store_true", help="finish an interrupted run in the same folder")
    r.add_argument("--no-progress", action="store_true", help="no progress bar (remarks still shown)")
    r.add_argument("--variants", type=int, metavar="N",
                   help="render variants 0..N-1 of the spec's 'variation:' section into OUT/variant_0000, ...")
    where = r.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N", help="render on a local Dask cluster of N worker processes")
    where.add_argument("--scheduler", metavar="ADDRESS", help="render on an existing Dask cluster, e.g. tcp://host:8786")
    pv = command("preview", cmd_preview, "a fast low-spp contact sheet of every view of a spec "
                                         "(image, depth, normals, ids) as one PNG")
    pv.add_argument("spec", type=Path, help="the scene spec (YAML)")
    pv.add_argument("-o", "--output", type=Path, help="the PNG to write (default: <spec>.preview.png)")
    pv.add_argument("--spp", type=int, default=4, help="samples per pixel of the preview (default 4)")
    pv.add_argument("--tile-width", type=int, default=160, help="width of one tile in pixels (default 160)")
    pv.add_argument("--variant", choices=RENDER_VARIANTS, help="Mitsuba variant (default: the spec's)")
    i = command("info", cmd_info, "summarise a dataset")
    i.add_argument("dataset", type=Path, help="a dataset folder written by 'scenegen render'")
    i.add_argument("--limit", type=int, default=10, help="views to list (default 10)")
    i.add_argument("--json", action="store_true", help="print the summary and every view's camera as JSON")
    f = command("verify", cmd_verify, "re-hash every file of a dataset against its manifest")
    f.add_argument("dataset", type=Path, help="a dataset folder")
    f.add_argument("--json", action="store_true", help="print the report as JSON")
    e = command("export", cmd_export, f"export a dataset to {', '.join(EXPORT_FORMATS)}")
    e.add_argument("dataset", type=Path, help="a dataset folder")
    e.add_argument("--format", required=True, choices=EXPORT_FORMATS, help="the target format (docs/crossview.md)")
    e.add_argument("-o", "--output", type=Path, help="destination folder, new or empty (default: <dataset>.<format>)")
    g = command("gallery", cmd_gallery, "a contact sheet of a rendered dataset (image, depth, normals, ids "
                                        "per view) as one PNG and an HTML page")
    g.add_argument("dataset", type=Path, help="a dataset folder")
    g.add_argument("-o", "--output", type=Path,
                   help="the PNG to write; the HTML page goes next to it (default: <dataset>.gallery.png)")
    g.add_argument("--tile-width", type=int, default=160, help="width of one tile in pixels (default 160)")
    x = command("examples", cmd_examples, "list the bundled example scenes and gate files, or copy them")
    x.add_argument("--copy", type=Path, metavar="DEST", help="copy scenes/ and gates/ into DEST")
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
    bad = next((a for a in (sys.argv[1:] if argv is None else argv) if "\x00" in str(a)), None)
    if bad is not None:  # no path, name or option can hold one
        return _err(f"the argument {str(bad)!r} contains a NUL byte")
    args = build_parser().parse_args(argv)
    args.verbosity = QUIET if args.quiet else VERBOSE if args.verbose else NORMAL
    t0 = time.perf_counter()
    try:
        code = args.fn(args)
        if args.verbosity >= VERBOSE:
            print(f"scenegen {args.cmd}: {time.perf_counter() - t0:.2f} s", file=sys.stderr)
        return code
    except SpecError as e:
        return _err(str(e), args)
    except Exception as e:  # bad input is told apart here; anything else propagates
        if isinstance(e, _bad_input_errors()):
            return _err(str(e), args)
        if isinstance(e, BrokenPipeError):  # output piped into e.g. `head`
            return 0
        if isinstance(e, OSError):  # a full disk, a read-only or forbidden folder: one line, exit 2
            return _err(os_error_message(e), args)
        raise
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
