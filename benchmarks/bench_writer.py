"""The writer's side of a frame (not a test; issue 32, "Writers that keep up"):

* ``codecs``: CPU per demo view (480x360) of encoding and hashing its files with each
  ``render.exr_compression``, the files' sizes, and whether OpenEXR (every file, bit-exact) and
  OpenCV (the linear image) read them back;
* ``pool``: views/s that the writer alone sustains (stage + commit of already rendered demo views,
  no render) with 1, 2, 4 writer threads, with each thread count's CPU per view;
* ``fixed``: the per-view fixed cost of tiny views (32x24, 4 spp, the full pipeline: render,
  truth, encode, writes, fsyncs, journal), as wall time per view over a run; run it from another
  checkout's copy to compare revisions (the code measured is the checkout's: benchmarks/_common.py).

Run: .venv/bin/python benchmarks/bench_writer.py [codecs] [pool] [fixed] [--views 200] [--repeat 5]
"""
from __future__ import annotations

import argparse
import hashlib
import io
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")  # before cv2 is imported

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, load  # noqa: E402

TINY = """
name: tiny
render: {{spp: 4, max_depth: 3}}
objects:
  - name: floor
    shape: {{type: plane, size: [4, 4]}}
    material: {{type: diffuse, texture: {{type: checkerboard, params: {{squares_u: 8, squares_v: 8}}}}}}
  - name: ball
    shape: {{type: sphere, radius: 0.4}}
    transform: {{translation: [0, 0, 0.4]}}
lights:
  - {{type: point, position: [1, -1, 3], intensity: 10}}
cameras:
  cam: {{model: pinhole, size: [32, 24], fov_deg: 60}}
views:
  - camera: cam
    orbit: {{center: [0, 0, 0.3], radius_m: 2.5, elevations_deg: [30], count: {n}}}
"""


def demo_view():
    from scenegen.pipeline.view import render_view_data
    from scenegen.render import load_scene
    from scenegen.spec import load_spec, resolve_views

    spec = load_spec(ROOT / "scenes/demo.yaml")
    view = resolve_views(spec)[1]
    built = load_scene(spec)
    image, linear, truth, extra = render_view_data(spec, built, 1, view, spp=4, seed=0)
    return view.name, dict(image=image, linear_rgb=linear, truth=truth, extra_files=extra)


def bench_codecs(repeat: int) -> None:
    import cv2
    import OpenEXR

    from scenegen.dataset.codecs.exr import EXR_COMPRESSIONS, decode_exr
    from scenegen.dataset.view_files import encode_view

    name, data = demo_view()
    kw = {k: v for k, v in data.items() if k != "extra_files"}
    print(f"codecs: one demo view (480x360), encode_view + SHA-256 of its files, CPU (process_time), median of"
          f" {repeat}; {load()}; OpenEXR {OpenEXR.OPENEXR_VERSION}, OpenCV {cv2.__version__}")
    tmp = Path(tempfile.mkdtemp())
    for comp, info in EXR_COMPRESSIONS.items():
        cpu = []
        for _ in range(repeat + 1):
            c = time.process_time()
            files = encode_view(name, exr_compression=comp, **kw)
            for d in files.values():
                hashlib.sha256(d).hexdigest()
            cpu.append(time.process_time() - c)
        sizes = {rel.replace(name, "V"): len(d) for rel, d in files.items()}
        exrs = {rel: d for rel, d in files.items() if rel.endswith(".exr")}
        exact = all(
            all(np.array_equal(np.asarray(a).view(np.uint32), np.asarray(b).view(np.uint32))
                for a, b in zip(decode_exr(d).values(), decode_exr(encode_view(name, **kw)[rel]).values()))
            for rel, d in exrs.items())
        lin = next(rel for rel in files if rel.endswith("_linear.exr"))
        (tmp / f"{comp}.exr").write_bytes(files[lin])
        img = cv2.imread(str(tmp / f"{comp}.exr"), cv2.IMREAD_UNCHANGED)
        cv_ok = img is not None and np.array_equal(img[..., ::-1], kw["linear_rgb"].astype(np.float32))
        print(f"  {comp:5s} CPU {1e3 * statistics.median(cpu[1:]):6.1f} ms; bytes "
              + ", ".join(f"{k} {v / 2**20:.2f} MiB" for k, v in sizes.items())
              + f"; all {sum(sizes.values()) / 2**20:.2f} MiB; OpenEXR bit-exact {exact}; OpenCV reads the linear"
              f" image {'yes, exact' if cv_ok else 'no'} (registry says {info.opencv_reads})")


def bench_pool(views: int, repeat: int) -> None:
    from scenegen.dataset import DatasetWriter
    from scenegen.dataset.background import BackgroundWriter

    name, data = demo_view()
    print(f"pool: {views} demo views (480x360, ZIP) staged and committed by the writer alone, no render; {load()}")
    root = Path(tempfile.mkdtemp())
    res: dict[int, list] = {1: [], 2: [], 4: []}
    for r in range(repeat):  # interleaved
        for n in res:
            w = DatasetWriter(root / f"p{n}_{r}", spec_sha256="0" * 64, seed=0, variant="x", versions={})
            t, c = time.perf_counter(), time.process_time()
            with BackgroundWriter(w, workers=n) as bg:
                for i in range(views):
                    bg.submit(f"v{i:05d}", **data)
            res[n].append((time.perf_counter() - t, time.process_time() - c))
            w.close()
    for n, rs in res.items():
        wall = [a for a, _ in rs]
        print(f"  {n} thread(s): {views / statistics.median(wall):.1f} views/s (min-max"
              f" {views / max(wall):.1f}-{views / min(wall):.1f}, {repeat} rounds), CPU"
              f" {1e3 * statistics.median([b for _, b in rs]) / views:.1f} ms per view")


def bench_fixed(views: int, repeat: int) -> None:
    from scenegen.pipeline.run import render_spec

    folder = Path(tempfile.mkdtemp())
    spec = folder / "tiny.yaml"
    spec.write_text(TINY.format(n=views))
    render_spec(spec, folder / "warm", progress=False)  # kernels compiled, caches filled
    per = []
    for r in range(repeat):
        t = time.perf_counter()
        c = time.process_time()
        s = render_spec(spec, folder / f"o{r}", progress=False)
        per.append(((time.perf_counter() - t) / s.views_rendered, (time.process_time() - c) / s.views_rendered))
    wall = [a for a, _ in per]
    print(f"fixed: {views} views of 32x24 px, 4 spp, whole `render_spec` (scene load included), {repeat} runs,"
          f" {load()}: {1e3 * statistics.median(wall):.1f} ms per view (min-max {1e3 * min(wall):.1f}-"
          f"{1e3 * max(wall):.1f}), CPU {1e3 * statistics.median([b for _, b in per]):.1f} ms per view")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("parts", nargs="*", default=["codecs", "pool", "fixed"])
    ap.add_argument("--views", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    if "codecs" in args.parts:
        bench_codecs(args.repeat)
    if "pool" in args.parts:
        bench_pool(min(args.views, 24), args.repeat)
    if "fixed" in args.parts:
        bench_fixed(args.views, args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
