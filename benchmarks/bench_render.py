"""Benchmarks of the main job (not tests): truth pass vs raw ray casting, s/frame, RSS drift.

Run: .venv/bin/python benchmarks/bench_render.py [--frames-rss 300]
Prints ratios measured in the same run; figures go to docs/performance.md.
"""
from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2**20


def best_of(fn, repeat: int) -> float:
    fn()  # warm (compiles kernels)
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames-rss", type=int, default=300)
    ap.add_argument("--repeat", type=int, default=10)
    args = ap.parse_args(argv)

    from scenegen.render.backend import load_mitsuba

    mi = load_mitsuba("auto")
    import drjit as dr

    from scenegen.geometry.camera import Camera
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene
    from scenegen.render.truth import camera_rays, truth_pass
    from scenegen.spec import load_spec, parse_spec, resolve_views

    print(f"variant {mi.variant()}, {dr.thread_count()} threads")
    spec = load_spec(ROOT / "scenes/demo.yaml")
    views = resolve_views(spec)
    built = build_scene(spec, spp=spec.render.spp, sampler=spec.render.sampler, max_depth=spec.render.max_depth)

    # 1. truth pass vs raw ray_intersect on the same rays, at 640x480
    cam = Camera.from_opencv(np.array([[560.0, 0, 320], [0, 560.0, 240], [0, 0, 1]]),
                             [-0.18, 0.05, 0.0007, -0.0004, -0.006], (640, 480))
    pose = views[0].cam_from_world
    world_from_cam = pose.inverse()
    d_world = (camera_rays(cam) @ world_from_cam.R.T).astype(np.float32)
    o = world_from_cam.t.astype(np.float32)
    ray = mi.Ray3f(mi.Point3f(*[np.full(len(d_world), c, np.float32) for c in o]),
                   mi.Vector3f(d_world[:, 0], d_world[:, 1], d_world[:, 2]))
    dr.eval(ray)

    def raw():
        si = built.scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=True)
        np.array(si.t)  # what a caller needs at least: the hit distance, on the host

    def truth():
        truth_pass(built.scene, cam, pose, built.id_tables)

    n_rays = len(d_world)
    t_raw = best_of(raw, args.repeat)
    t_truth = best_of(truth, args.repeat)
    print(f"ray_intersect only (t to numpy): {t_raw * 1e3:.1f} ms = {n_rays / t_raw / 1e6:.1f} Mrays/s")
    print(f"truth pass (all 10 outputs to numpy): {t_truth * 1e3:.1f} ms = {n_rays / t_truth / 1e6:.1f} Mrays/s")
    print(f"RATIO truth/raw throughput: {t_raw / t_truth:.2f} (target >= 0.5)")

    # 2. steady-state seconds per frame of the demo scene (render + truth, no disk)
    cam_name = views[0].camera

    def frame(v=views[1]):
        render_view(built, cam_name, v.cam_from_world, spp=spec.render.spp, seed=1)
        truth_pass(built.scene, built.cameras[cam_name], v.cam_from_world, built.id_tables)

    t_frame = best_of(frame, 3)
    c = built.cameras[cam_name]
    print(f"demo frame ({c.width}x{c.height}, {spec.render.spp} spp, render + truth): {t_frame:.2f} s")

    # 3. RSS over many frames of a small scene: new poses every frame, kernels reused
    small = parse_spec((ROOT / "scenes/demo.yaml").read_text().replace("size: [480, 360]", "size: [160, 120]")
                       .replace("count: 8", f"count: {args.frames_rss}"), base_dir=ROOT / "scenes")
    sv = resolve_views(small)
    sb = build_scene(small, spp=4, sampler="ldsampler", max_depth=2)
    samples = []
    t0 = time.perf_counter()
    for i, v in enumerate(sv):
        render_view(sb, v.camera, v.cam_from_world, spp=4, seed=i)
        truth_pass(sb.scene, sb.cameras[v.camera], v.cam_from_world, sb.id_tables)
        if i % 25 == 0 or i == len(sv) - 1:
            samples.append((i, rss_mb()))
    dt = time.perf_counter() - t0
    first, last = samples[1][1], samples[-1][1]  # skip frame 0 (before warm-up allocations)
    print(f"{len(sv)} frames (160x120, 4 spp) in {dt:.1f} s; RSS after frame {samples[1][0]}: {first:.0f} MB, "
          f"after frame {samples[-1][0]}: {last:.0f} MB, drift {last - first:+.1f} MB")
    print("RSS samples (frame, MB):", ", ".join(f"({i}, {m:.0f})" for i, m in samples))
    return 0


if __name__ == "__main__":
    sys.exit(main())
