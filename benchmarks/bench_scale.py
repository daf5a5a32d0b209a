"""Scale benchmarks (not tests): RSS and per-view cost over many frames of the full pipeline,
the manifest journal from 10 to 100,000 views (record cost, journal size, compaction, resume),
and throughput in this process vs 1 and 2 Dask workers, with a projection for a cluster.

Run: .venv/bin/python benchmarks/bench_scale.py [--frames-rss 1000] [--frames-tput 48] [--views-journal 10000]
Prints figures measured in the same run; they go to docs/performance.md ("Scale").
"""
from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import load, rss_mb, target  # noqa: E402

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


def write_spec(folder: Path, name: str, *, n: int, w: int, h: int, spp: int) -> Path:
    p = folder / f"{name}.yaml"
    p.write_text(SPEC.format(n=n, w=w, h=h, spp=spp))
    return p


def bench_rss(folder: Path, frames: int) -> None:
    """The full pipeline (render, truth, encode, atomic writes, manifest) over many frames."""
    from scenegen.dataset import DatasetWriter
    from scenegen.pipeline.run import render_spec

    spec = write_spec(folder, "rss", n=frames, w=64, h=48, spp=4)
    samples: list[tuple[float, float, int]] = []  # (seconds, RSS MB, views complete)
    stop = threading.Event()
    out = folder / "rss_out"
    recorded: list[float] = []  # when each view was recorded (its journal line fsync'd)
    real_record = DatasetWriter.record_view

    def record_view(self, view, hashes):
        real_record(self, view, hashes)
        recorded.append(time.perf_counter())

    def sample():
        t0 = time.perf_counter()
        while not stop.wait(0.25):
            samples.append((time.perf_counter() - t0, rss_mb(), len(recorded)))

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    DatasetWriter.record_view = record_view
    t = time.perf_counter()
    try:
        s = render_spec(spec, out, progress=False)
    finally:
        DatasetWriter.record_view = real_record
    dt = time.perf_counter() - t
    stop.set()
    th.join()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    early = [r for _, r, d in samples if 50 <= d <= 100]
    late = [r for _, r, d in samples if d >= frames - 100]
    print(f"RSS over {s.views_rendered} frames (64x48, 4 spp, full pipeline, one process): "
          f"{dt:.1f} s ({s.views_rendered / dt:.1f} views/s)")
    if early and late:
        print(f"  RSS at frames 50-100: {min(early):.0f}-{max(early):.0f} MB; at the last 100: "
              f"{min(late):.0f}-{max(late):.0f} MB; drift {max(late) - max(early):+.1f} MB; peak (ru_maxrss) {peak:.0f} MB")
    print(f"  manifest.json at the end: {(out / 'manifest.json').stat().st_size / 1024:.0f} KiB (written at the"
          f" start and at the end; views were recorded in the journal)")
    # the cost of a view: the interval between consecutive recordings, near view 10 and the last
    gaps = [b - a for a, b in zip(recorded, recorded[1:])]
    if len(gaps) >= 220:
        early, late = block_medians(gaps, 5), block_medians(gaps[::-1], 0)
        print(f"  per-view cost: {1e3 * statistics.median(early):.1f} ms at views 5-105,"
              f" {1e3 * statistics.median(late):.1f} ms at the last 100 views")
        print("  (drifts with the machine's load over the run; the target is measured by bench_view_cost)")


def bench_view_cost(folder: Path, at: int = 1000, block: int = 20, rounds: int = 5) -> None:
    """Per-view cost of the full pipeline (render, truth, encode, writer thread, journal) at view
    ``at`` vs view 10, as interleaved rounds: ``block`` views of a dataset that already holds
    ``at`` views, then ``block`` views of one that holds 10, and again, so that the machine's
    load drifting over the run does not enter the ratio."""
    from scenegen.dataset import DatasetWriter
    from scenegen.dataset.background import BackgroundWriter
    from scenegen.pipeline.view import render_view_data
    from scenegen.render import load_scene
    from scenegen.spec import load_spec, resolve_views

    n = at + block * rounds + 10
    spec = load_spec(write_spec(folder, "cost", n=n, w=64, h=48, spp=4))
    views = resolve_views(spec)
    built = load_scene(spec, spp=4)
    big = DatasetWriter(folder / "cost_big", spec_sha256="0" * 64, seed=0, variant=built.variant, versions={})
    runs = [0]

    def views_into(writer, indices) -> float:
        handed = []
        with BackgroundWriter(writer) as bg:
            for i in indices:
                image, linear, truth, extra = render_view_data(spec, built, i, views[i], spp=4, seed=0)
                bg.submit(views[i].name, image=image, linear_rgb=linear, truth=truth, extra_files=extra)
                handed.append(time.perf_counter())
        return (handed[-1] - handed[0]) / (len(handed) - 1)

    views_into(big, range(at))  # the dataset as it is at view `at`
    small_t, big_t = [], []
    for r in range(rounds):
        runs[0] += 1
        small = DatasetWriter(folder / f"cost_small{runs[0]}", spec_sha256="0" * 64, seed=0, variant=built.variant,
                              versions={})
        views_into(small, range(10))
        small_t.append(views_into(small, range(10, 10 + block)))
        big_t.append(views_into(big, range(at + block * r, at + block * (r + 1))))
    print(f"per-view cost, 64x48, 4 spp, full pipeline, {rounds} interleaved rounds of {block} views, {load()}:"
          f" {1e3 * statistics.median(small_t):.1f} ms at view 10, {1e3 * statistics.median(big_t):.1f} ms at view {at}")
    print("  " + target(f"per-view cost at view {at} / view 10", [b / a for a, b in zip(small_t, big_t)], 1.1))


def block_medians(values, start: int, blocks: int = 5, size: int = 20) -> list[float]:
    """Medians of ``blocks`` consecutive blocks of ``size`` values from ``start``."""
    return [statistics.median(values[start + size * i: start + size * (i + 1)]) for i in range(blocks)]


def bench_journal(folder: Path, views: int, big: int = 100_000) -> None:
    """Recording a view (one fsync'd journal line) from view 10 to ``views``; then, for ``big``
    tiny views, the journal's size, the compaction into manifest.json and the resume time."""
    from scenegen import dataset as ds
    from scenegen.dataset import journal

    def writer(name, n):
        w = ds.DatasetWriter(folder / name, spec_sha256="0" * 64, seed=0, variant="llvm_ad_rgb", versions={})
        names = [f"cam_{i:06d}" for i in range(n)]
        w.write_cameras({v: {"camera": {}, "cam_from_world": {}} for v in names}, {})
        return w, names

    hashes = lambda i, n: {rel: f"{i:064x}" for rel in ds.view_paths(n).values()}  # noqa: E731
    w, names = writer("journal", views)
    times, cpu = [], []
    for i, n in enumerate(names):
        t, c = time.perf_counter(), time.process_time()
        w.record_view(n, hashes(i, n))
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    per_line = w.journal_bytes / views
    t = time.perf_counter()
    w.close()
    t_close = time.perf_counter() - t
    at = lambda k: statistics.median(times[max(0, k - 10):k + 10])  # noqa: E731
    marks = [10, 100, 1000, views - 10]
    print(f"record_view (one fsync'd journal line) over {views} views, {load()}: "
          + ", ".join(f"{1e3 * at(k):.2f} ms at view {k}" for k in marks if k < views)
          + f"; {per_line:.0f} bytes per view; compaction at the end {1e3 * t_close:.0f} ms")
    # the wall time is mostly the fdatasync, i.e. the disk and whoever else writes to it; the CPU
    # time is the writer's own work (what would grow with the run if anything did)
    print(f"  CPU per record: {1e3 * statistics.mean(cpu[5:105]):.3f} ms at views 5-105,"
          f" {1e3 * statistics.mean(cpu[-100:]):.3f} ms at the last 100")
    early, late = block_medians(times, 5), block_medians(times[::-1], 0)  # skip the journal's creation
    print("  " + target(f"record_view wall time at view {views} / view 10", [b / a for a, b in zip(early, late)], 1.1))
    early = [statistics.mean(cpu[5 + 100 * i: 105 + 100 * i]) for i in range(3)]
    late = [statistics.mean(cpu[len(cpu) - 100 * (i + 1): len(cpu) - 100 * i]) for i in range(3)]
    print("  " + target(f"record_view CPU time at view {views} / view 10", [b / a for a, b in zip(early, late)], 1.1))

    # `big` tiny views: a killed run's journal (written here without fsyncs: same bytes), then resume
    w, names = writer("big", big)
    w.abort()  # the run is killed here: the OS drops its lock on the folder (scenegen/dataset/lock.py)
    root = folder / "big"
    sha = ds.load_current_manifest(root)["manifest_sha256"]
    lines = [journal.encode_line(0, journal.header(sha))]
    lines += [journal.encode_line(i + 1, journal.view_record(n, hashes(i, n))) for i, n in enumerate(names)]
    (root / "manifest.journal").write_bytes(b"".join(lines))
    size = (root / "manifest.journal").stat().st_size
    t = time.perf_counter()
    m = ds.load_current_manifest(root)
    t_read = time.perf_counter() - t
    t = time.perf_counter()
    w2 = ds.DatasetWriter(root, spec_sha256="0" * 64, seed=0, variant="llvm_ad_rgb", versions={}, resume=True)
    t_resume = time.perf_counter() - t
    resumed = len(w2.completed_views)
    w2.abort()  # release the folder (the resume compacted the journal already)
    t = time.perf_counter()
    ds.DatasetWriter(root, spec_sha256="0" * 64, seed=0, variant="llvm_ad_rgb", versions={}, resume=True).abort()
    t_reopen = time.perf_counter() - t
    assert resumed == big == sum(e["status"] == "complete" for e in m["views"].values())
    print(f"{big} tiny views (5 files each): journal {size / 2**20:.1f} MiB ({size / big:.0f} bytes/view);"
          f" reading manifest + journal {t_read:.1f} s; resume after a kill (check, replay, compact)"
          f" {t_resume:.1f} s; manifest.json {(root / 'manifest.json').stat().st_size / 2**20:.1f} MiB;"
          f" reopening the compacted dataset {t_reopen:.1f} s")


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
    print(f"  this process (serial):   {serial:6.2f} views/s")
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
              f"(scene load + kernel compile per worker); warm {frames / warm:6.2f} views/s "
              f"({results[n] / serial:.2f}x serial)")
    print(f"  2 vs 1 workers: {results[2] / results[1]:.2f}x")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames-rss", type=int, default=1000)
    ap.add_argument("--frames-tput", type=int, default=48)
    ap.add_argument("--size", type=int, nargs=2, default=(160, 120))
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--skip-rss", action="store_true")
    ap.add_argument("--views-journal", type=int, default=10000)
    ap.add_argument("--views-big", type=int, default=100_000)
    args = ap.parse_args(argv)
    from scenegen.render.backend import load_mitsuba

    load_mitsuba("auto")
    with tempfile.TemporaryDirectory() as tmp:
        if not args.skip_rss:
            bench_rss(Path(tmp), args.frames_rss)
        bench_view_cost(Path(tmp))
        bench_journal(Path(tmp), args.views_journal, args.views_big)
        bench_throughput(Path(tmp), args.frames_tput, *args.size, args.spp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
