"""A whole frame vs the render alone (not a test): the demo at its 16 spp and at 4 spp.

A frame of a serial run is: render, truth pass, sRGB encoding, then (on the writer thread,
scenegen/dataset/background.py) truth checks, EXR/PNG encoding, SHA-256, atomic fsync'd writes
and the journal line. Steady state, per frame: (time of the last view's hand-over - the first's)
/ (views - 1), the same for the render alone (first to last render's end); runs interleaved
(render, pipeline, serial, render, ...), ratios per round.

Also printed: the serial pipeline (writing on the render's thread, as before the writer thread)
and the CPU accounting that bounds any overlap on this machine: with the render using c cores
of n, the frame cannot be shorter than (render CPU + the rest's CPU) / n.

Run: .venv/bin/python benchmarks/bench_frame.py [--reps 3] [--views 8] [--spp 16 4] [--render-threads N]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, interleaved, load, ratios, target  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--views", type=int, default=8)
    ap.add_argument("--spp", type=int, nargs="+", default=[16, 4])
    ap.add_argument("--render-threads", type=int, help="Dr.Jit threads (default: all cores); fewer leaves"
                    " cores to the writer thread, showing what the overlap does when the render leaves room")
    args = ap.parse_args(argv)

    from scenegen.dataset import DatasetWriter
    from scenegen.dataset.background import BackgroundWriter
    from scenegen.pipeline.view import render_view_data, view_seed
    from scenegen.render import load_scene
    from scenegen.spec import load_spec, resolve_views

    spec = load_spec(ROOT / "scenes/demo.yaml")
    views = resolve_views(spec)[: args.views]
    tmp = Path(tempfile.mkdtemp(prefix="bench_frame_"))
    runs = [0]

    for spp in args.spp:
        built = load_scene(spec, spp=spp)
        if args.render_threads:
            import drjit as dr  # after load_scene: the libLLVM is chosen first

            dr.set_thread_count(args.render_threads)
        cam = built.cameras[views[0].camera]
        seed = spec.render.seed

        def render_only():
            ends = []
            for i, v in enumerate(views):
                built.render(v.camera, v.cam_from_world, spp=spp, seed=view_seed(seed, i), motion=v.motion,
                             light_scales=v.light_scales)
                ends.append(time.perf_counter())
            return (ends[-1] - ends[0]) / (len(views) - 1)

        def pipeline(background: bool):
            runs[0] += 1
            w = DatasetWriter(tmp / f"run{runs[0]}", spec_sha256="0" * 64, seed=seed, variant=built.variant,
                              versions={})
            handed = []
            bg = BackgroundWriter(w) if background else None
            for i, v in enumerate(views):
                image, linear, truth, extra = render_view_data(spec, built, i, v, spp=spp, seed=seed)
                if bg is not None:
                    bg.submit(v.name, image=image, linear_rgb=linear, truth=truth, extra_files=extra)
                else:
                    w.write_view(v.name, image=image, linear_rgb=linear, truth=truth, extra_files=extra)
                handed.append(time.perf_counter())
            if bg is not None:
                bg.close()
            w.close()
            return (handed[-1] - handed[0]) / (len(views) - 1)

        def cpu(fn):
            c0, t0 = time.process_time(), time.perf_counter()
            fn()
            return (time.process_time() - c0) / (time.perf_counter() - t0), time.process_time() - c0

        render_only()
        pipeline(True)  # warm: kernels, first-use costs
        r = interleaved({"render": render_only, "frame": lambda: pipeline(True),
                         "serial": lambda: pipeline(False)}, args.reps)
        util_r, cpu_r = cpu(render_only)
        util_f, cpu_f = cpu(lambda: pipeline(True))
        n = len(views)
        threads = f", render on {args.render_threads} thread(s)" if args.render_threads else ""
        print(f"demo {cam.width}x{cam.height}, {spp} spp, {n} views{threads}, {load()}")
        print(f"  render alone {fmt(r['render'], ' ms', 1e3, 1)}; frame (writer thread) {fmt(r['frame'], ' ms', 1e3, 1)};"
              f" serial frame {fmt(r['serial'], ' ms', 1e3, 1)}")
        print(f"  CPU: render {1e3 * cpu_r / n:.0f} ms/frame ({util_r:.2f} cores busy), whole frame"
              f" {1e3 * cpu_f / n:.0f} ms/frame ({util_f:.2f} cores); the rest needs"
              f" {1e3 * (cpu_f - cpu_r) / n:.0f} ms of CPU per frame")
        floor = max(1.0, (cpu_f / n) / os.cpu_count() / (min(r["render"])))
        print(f"  overlap bound on this machine: frame >= {floor:.2f} x render (all {os.cpu_count()} cores busy)")
        print(f"  serial / render: {fmt(ratios(r['serial'], r['render']))}")
        print("  " + target(f"frame / render, demo {spp} spp", ratios(r["frame"], r["render"]), 1.05))
    return 0


if __name__ == "__main__":
    sys.exit(main())
