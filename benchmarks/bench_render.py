"""Benchmarks of the main job (not tests): truth pass vs raw ray casting and vs a float32
all-outputs ceiling, cross-view correspondences vs the truth pass, s/frame, RSS drift.

Run: .venv/bin/python benchmarks/bench_render.py [--frames-rss 300] [--repeat 10]
Prints ratios measured in the same run; figures go to docs/performance.md.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, interleaved, load, ratios, rss_mb, target, timed  # noqa: E402


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
    from scenegen.render.arrays import aligned, to_jit
    from scenegen.render.frames import render_view
    from scenegen.pipeline.view import correspond_points
    from scenegen.render.scene import build_scene
    from scenegen.render.truth import camera_rays, truth_pass
    from scenegen.spec import load_spec, parse_spec, resolve_views

    print(f"variant {mi.variant()}, {dr.thread_count()} threads")
    spec = load_spec(ROOT / "scenes/demo.yaml")
    views = resolve_views(spec)
    built = build_scene(spec, spp=spec.render.spp, sampler=spec.render.sampler, max_depth=spec.render.max_depth)

    # 1. truth pass vs raw ray_intersect and vs a float32 all-outputs ceiling on the same rays,
    # and the cross-view correspondences of one direction, at 640x480 (interleaved rounds)
    cam = Camera.from_opencv(np.array([[560.0, 0, 320], [0, 560.0, 240], [0, 0, 1]]),
                             [-0.18, 0.05, 0.0007, -0.0004, -0.006], (640, 480))
    pose = views[0].cam_from_world
    world_from_cam = pose.inverse()
    d_cam64 = camera_rays(cam)
    d_world = aligned(d_cam64 @ world_from_cam.R.T, np.float32)
    d_cam = aligned(d_cam64, np.float32)
    o = world_from_cam.t.astype(np.float32)
    n_rays = len(d_world)
    col = lambda a, i: to_jit(mi.Float, a[:, i], np.float32)  # noqa: E731
    ray = mi.Ray3f(mi.Point3f(*[dr.opaque(mi.Float, float(c)) for c in o]), mi.Vector3f(*[col(d_world, i) for i in range(3)]))
    dc = mi.Vector3f(*[col(d_cam, i) for i in range(3)])
    Rcw = [[dr.opaque(mi.Float, float(pose.R[i, j])) for j in range(3)] for i in range(3)]
    dr.eval(ray, dc)
    obj_table, inst_table = built.id_tables
    flags = mi.RayFlags.Minimal | mi.RayFlags.UV | mi.RayFlags.ShadingFrame

    def raw():
        si = built.scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=True)
        np.array(si.t)  # what a caller needs at least: the hit distance, on the host

    def ceiling():
        """Every output of the truth pass, in float32, in one kernel, to numpy without copies."""
        si = built.scene.ray_intersect(ray, ray_flags=flags, coherent=True)
        hit = si.is_valid()
        t = dr.select(hit, si.t, dr.inf)
        tp = dr.select(hit, si.t, dr.nan)
        n = dr.select(hit, dr.normalize(si.sh_frame.n), dr.nan)
        n_cam = mi.Vector3f(*[Rcw[i][0] * n.x + Rcw[i][1] * n.y + Rcw[i][2] * n.z for i in range(3)])
        sid = dr.select(hit, dr.reinterpret_array(mi.UInt32, si.shape), 0)
        outs = [t, t * dc.z, dc * tp, ray.o + ray.d * tp, n, n_cam, dr.select(hit, si.uv, dr.nan),
                dr.select(hit, dr.gather(mi.UInt32, obj_table, sid), 0),
                dr.select(hit, dr.gather(mi.UInt32, inst_table, sid), 0), hit]
        dr.eval(*outs)
        for x in outs:
            for c in (x if dr.depth_v(x) > 1 else [x]):
                c.numpy()

    def truth():
        truth_pass(built.scene, cam, pose, built.id_tables, as_stored=True)  # the pipeline's call

    tr = built.truth(cam, pose)
    P = np.where(tr["valid"][..., None], tr["points_world"], np.nan)
    others = [v.cam_from_world for v in views[1:]]
    k = [0]

    def crossview():  # one direction as the pipeline calls it: a new camera pose each call, as in a run
        k[0] += 1
        correspond_points(built, P, cam, others[k[0] % len(others)])

    for f in (raw, ceiling, truth, crossview):
        f()
        f()
    r = interleaved({"raw": lambda: timed(raw), "ceiling": lambda: timed(ceiling), "truth": lambda: timed(truth),
                     "crossview": lambda: timed(crossview)}, args.repeat)
    print(f"640x480 rays, demo scene, {load()}:")
    print(f"  ray_intersect only (t to numpy): {fmt(r['raw'], ' ms', 1e3, 1)}"
          f" = {n_rays / min(r['raw']) / 1e6:.1f} Mrays/s at best")
    print(f"  float32 all-outputs ceiling (one kernel, to numpy): {fmt(r['ceiling'], ' ms', 1e3, 1)}")
    print(f"  truth pass (as stored; float64 derivation, planar float32 out): {fmt(r['truth'], ' ms', 1e3, 1)}")
    print(f"  crossview, one direction (projection + visibility + states, one kernel): {fmt(r['crossview'], ' ms', 1e3, 1)}")
    print(f"  truth / raw throughput: {fmt(ratios(r['raw'], r['truth']))}")
    print("  " + target("truth pass throughput / float32 ceiling", ratios(r["ceiling"], r["truth"]), 0.8, at_most=False))
    print("  " + target("crossview per direction / truth pass", ratios(r["crossview"], r["truth"]), 1.2))

    # 2. steady-state seconds per frame of the demo scene (render + truth, no disk)
    cam_name = views[0].camera

    def frame(v=views[1]):
        render_view(built.device, cam_name, v.cam_from_world, spp=spec.render.spp, seed=1)
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
        render_view(sb.device, v.camera, v.cam_from_world, spp=4, seed=i)
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
