"""Scale benchmarks (not tests): RSS over many frames of the full pipeline, and throughput in this
process vs 1 and 2 Dask workers, with a projection for a cluster.

Run: .venv/bin/python benchmarks/bench_scale.py [--frames-rss 1000] [--frames-tput 48]
Prints figures measured in the same run; they go to docs/performance.md ("Scale").
"""
from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import threading
import time
from pathlib import Path

SPEC = """
name: scale
render: {{spp: {spp}, max_depth: 3}}
objects:
  - name: floor
    shape: {{type: plane, size: [4, 4]}}
    material: {{type: diffuse, texture: {{type: checkerboard, params: {{squares_u: 8, squares_v: 8}}}}}}
  - name: rock
    shape: {{type: blob, radius: 0.4, subdivisions: 4}}
    transform: {{translation: [0, 0, 0.4]}}
    material: {{type: plastic, texture: {{type: noise, params: {{size_px: 128}}}}}}
lights:
  - {{type: point, position: [1, -1, 3], intensity: 10}}
  - {{type: constant, radiance: 0.1}}
cameras:
  cam: {{model: opencv, size: [{w}, {h}], fov_deg: 60, dist: [-0.1, 0.01, 0, 0]}}
views:
  - camera: cam
    orbit: {{center: [0, 0, 0.3], radius_m: 2.5, elevations_deg: [30], count: {n}}}
"""


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20


def write_spec(folder: Path, name: str, *, n: int, w: int, h: int, spp: int) -> Path:
    p = folder / f"{name}.yaml"
    p.write_text(SPEC.format(n=n, w=w, h=h, spp=spp))
    return p


def bench_rss(folder: Path, frames: int) -> None:
    """The full pipeline (render, truth, encode, atomic writes, manifest) over many frames."""
    from scenegen.pipeline.run import render_spec

    spec = write_spec(folder, "rss", n=frames, w=64, h=48, spp=4)
    samples: list[tuple[float, float, int]] = []  # (seconds, RSS MB, views complete)
    stop = threading.Event()
    out = folder / "rss_out"

    def sample():
        import json

        t0 = time.perf_counter()
        while not stop.wait(0.25):
            try:
                done = sum(e["status"] == "complete" for e in
                           json.loads((out / "manifest.json").read_text())["views"].values())
            except (OSError, ValueError, KeyError):
                done = 0
            samples.append((time.perf_counter() - t0, rss_mb(), done))

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    t = time.perf_counter()
    s = render_spec(spec, out, progress=False)
    dt = time.perf_counter() - t
    stop.set()
    th.join()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    early = [r for _, r, d in samples if 50 <= d <= 100]
    late = [r for _, r, d in samples if d >= frames - 100]
    print(f"RSS over {s.views_rendered} frames (64x48, 4 spp, full pipeline, one process): "
          f"{dt:.1f} s ({s.views_rendered / dt:.1f} frames/s)")
    if early and late:
        print(f"  RSS at frames 50-100: {min(early):.0f}-{max(early):.0f} MB; at the last 100: "
              f"{min(late):.0f}-{max(late):.0f} MB; drift {max(late) - max(early):+.1f} MB; peak (ru_maxrss) {peak:.0f} MB")
    # the manifest is rewritten after every view: its size grows with the run (cost O(views^2))
    print(f"  manifest.json at the end: {(out / 'manifest.json').stat().st_size / 1024:.0f} KiB")
    # what rate did the run keep late vs early (manifest rewrite cost)?
    if len(samples) > 8:
        (t1, _, d1), (t2, _, d2) = samples[len(samples) // 8], samples[len(samples) // 4]
        (t3, _, d3), (t4, _, d4) = samples[-len(samples) // 4], samples[-2]
        if t2 > t1 and t4 > t3:
            print(f"  frames/s early {(d2 - d1) / (t2 - t1):.1f}, late {(d4 - d3) / (t4 - t3):.1f}")


def bench_manifest(folder: Path, views: int) -> None:
    """The client's share per view: record_view rewrites the manifest, whose size grows with the run."""
    from scenegen import dataset as ds

    w = ds.DatasetWriter(folder / "manifest_only", spec_sha256="0" * 64, seed=0, variant="llvm_ad_rgb",
                         versions={})
    names = [f"cam_{i:05d}" for i in range(views)]
    w.write_cameras({n: {"camera": {}, "cam_from_world": {}} for n in names}, {})
    marks = {max(1, views // 10), views // 2, views - 1}
    t_prev, out = time.perf_counter(), []
    for i, n in enumerate(names):
        t = time.perf_counter()
        w.record_view(n, {rel: f"{i:064x}" for rel in ds.view_paths(n).values()})
        if i in marks:
            out.append(f"{1e3 * (time.perf_counter() - t):.1f} ms at view {i}")
    total = time.perf_counter() - t_prev
    print(f"record_view (manifest rewrite) over {views} views: {total:.1f} s in all; " + ", ".join(out))


def bench_throughput(folder: Path, frames: int, w: int, h: int, spp: int) -> None:
    from scenegen.pipeline.distributed import open_client
    from scenegen.pipeline.run import render_spec
    import drjit as dr  # main() has called load_mitsuba, which sets the libLLVM first

    spec = write_spec(folder, "tput", n=frames, w=w, h=h, spp=spp)
    print(f"throughput: {frames} frames of {w}x{h}, {spp} spp, blob + textured floor, Dr.Jit "
          f"{dr.thread_count()} threads per process, {os.cpu_count()} cores")
    render_spec(spec, folder / "warm", progress=False, frames="0-1")  # compile kernels here
    t = time.perf_counter()
    s = render_spec(spec, folder / "serial", progress=False)
    serial = s.views_rendered / (time.perf_counter() - t)
    print(f"  this process (serial):   {serial:6.2f} frames/s")
    results = {}
    for n in (1, 2):
        t0 = time.perf_counter()
        with open_client(workers=n) as client:
            t_start = time.perf_counter() - t0
            t = time.perf_counter()
            render_spec(spec, folder / f"w{n}_cold", progress=False, dask_client=client)
            cold = time.perf_counter() - t
            t = time.perf_counter()
            render_spec(spec, folder / f"w{n}_warm", progress=False, dask_client=client)
            warm = time.perf_counter() - t
        results[n] = frames / warm
        print(f"  {n} Dask worker(s): cluster start {t_start:.1f} s; first run {cold:.1f} s "
              f"(scene load + kernel compile per worker); warm {frames / warm:6.2f} frames/s "
              f"({results[n] / serial:.2f}x serial)")
    print(f"  2 vs 1 workers: {results[2] / results[1]:.2f}x")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames-rss", type=int, default=1000)
    ap.add_argument("--frames-tput", type=int, default=48)
    ap.add_argument("--size", type=int, nargs=2, default=(160, 120))
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--skip-rss", action="store_true")
    ap.add_argument("--views-manifest", type=int, default=2000)
    args = ap.parse_args(argv)
    from scenegen.render.backend import load_mitsuba

    load_mitsuba("auto")
    with tempfile.TemporaryDirectory() as tmp:
        if not args.skip_rss:
            bench_rss(Path(tmp), args.frames_rss)
        bench_manifest(Path(tmp), args.views_manifest)
        bench_throughput(Path(tmp), args.frames_tput, *args.size, args.spp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
