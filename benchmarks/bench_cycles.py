"""Mitsuba (this project) vs Blender Cycles (`bpy`, the renderer Kubric uses) on the same picture.

The same meshes (a textured blob and a textured floor, world-frame triangles with the same UVs
and vertex normals), the same textures (linear, bilinear, repeating), the same light (a uniform
environment of radiance 1: exact in both renderers' units), the same pinhole camera, resolution,
samples per pixel, path depth and box filter, no denoising, 2 threads each, both warm. Reports the
warm time ratio and the image difference next to Mitsuba's own seed-to-seed noise, so that it is
clear the comparison is of the same picture. The whole frame (render, truth pass,
encoding and writing, the writer thread overlapping the next render, as in a run) is timed too;
``--plan`` adds the measurements behind the plan for 0.25 x Cycles (docs/performance.md): cost
per sample vs fixed cost, our sensor vs Mitsuba's built-in perspective camera, the indirect
bounce, the thread count, and Cycles' own time per sample.

bpy is big and optional: it lives only in its own environment, never in .venv or pyproject.
    .venv/bin/python benchmarks/bench_cycles.py --setup      # creates benchmarks/.venv-bpy (bpy==5.0.1)
    .venv/bin/python benchmarks/bench_cycles.py [--size 320 240] [--spp 64] [--plan]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _common import load, target  # noqa: E402
BPY_VENV = HERE / ".venv-bpy"
BPY_PIN = "bpy==5.0.1"  # Blender 5.0.1; wheels for CPython 3.11

SPEC = """
name: cycles_cmp
render: {{spp: {spp}, max_depth: {depth}, sampler: ldsampler}}
objects:
  - name: floor
    shape: {{type: plane, size: [4, 4]}}
    material: {{type: diffuse, texture: {{type: checkerboard, params: {{squares_u: 8, squares_v: 8}}}}}}
  - name: rock
    shape: {{type: blob, radius: 0.5, subdivisions: 5}}
    transform: {{translation: [0, 0, 0.5]}}
    material: {{type: diffuse, texture: {{type: noise, params: {{size_px: 256}}}}}}
lights:
  - {{type: constant, radiance: 1.0}}
cameras:
  cam: {{model: pinhole, size: [{w}, {h}], fx: {f}, fy: {f}, cx: {cx}, cy: {cy}}}
views:
  - camera: cam
    look_at: [{{eye: [2.2, -2.2, 1.6], target: [0, 0, 0.4]}}]
"""


def setup() -> int:
    if not (BPY_VENV / "bin" / "python").is_file():
        subprocess.check_call([sys.executable, "-m", "venv", str(BPY_VENV)])
    return subprocess.call([str(BPY_VENV / "bin" / "python"), "-m", "pip", "install", BPY_PIN, "numpy"])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--setup", action="store_true", help=f"create {BPY_VENV} with {BPY_PIN}")
    ap.add_argument("--size", type=int, nargs=2, default=(320, 240))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--max-depth", type=int, default=3, help="Mitsuba path depth (Cycles bounces = depth - 2)")
    ap.add_argument("--keep", metavar="DIR", help="save both images there as .npy")
    ap.add_argument("--plan", action="store_true", help="also measure what the plan for 0.25 x Cycles rests on")
    ap.add_argument("--frames", type=int, default=5, help="frames of the whole-frame measurement")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds of Mitsuba and Cycles timings")
    args = ap.parse_args(argv)
    if args.setup:
        return setup()
    py = BPY_VENV / "bin" / "python"
    if not py.is_file():
        print(f"no bpy environment: run {Path(__file__).name} --setup first (installs {BPY_PIN} into {BPY_VENV})")
        return 2

    from scenegen.render.backend import load_mitsuba

    mi = load_mitsuba("auto")
    import drjit as dr

    from scenegen.dataset import codecs as sio
    from scenegen.geometry.conventions import blender_matrix_world
    from scenegen.assets.meshes import texture_image
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene
    from scenegen.spec import parse_spec, resolve_views

    W, H = args.size
    f = 0.9 * W
    spec = parse_spec(SPEC.format(spp=args.spp, depth=args.max_depth, w=W, h=H, f=f, cx=(W - 1) / 2,
                                  cy=(H - 1) / 2), file="bench_cycles")
    view = resolve_views(spec)[0]
    built = build_scene(spec, spp=args.spp, sampler="ldsampler", max_depth=args.max_depth)
    dr.set_thread_count(2)
    render = lambda seed: render_view(built.device, "cam", view.cam_from_world, spp=args.spp, seed=seed)
    t = time.perf_counter()
    render(1)
    mi_cold = time.perf_counter() - t
    times = []
    for s in (2, 3):
        t = time.perf_counter()
        render(s)
        times.append(time.perf_counter() - t)
    mi_warm = min(times)
    img_a, img_b = render(11), render(12)  # two seeds: Mitsuba's own noise
    whole_frame(spec, built, view, args.spp, 2)  # warm: the writer thread's first use
    plan = mitsuba_plan(spec, built, view, args, render) if args.plan else []

    with tempfile.TemporaryDirectory() as tmp:
        data = {"settings": np.array([W, H, args.spp, args.max_depth - 2, 2]), "env_radiance": np.array(1.0),
                "focal_px": np.array(f), "blender_matrix_world": blender_matrix_world(view.cam_from_world),
                "objects": np.array([o.name for o in spec.objects])}
        for o in spec.objects:
            mesh = built.meshes_world[o.name]
            data[f"{o.name}.vertices"] = np.asarray(mesh.vertices, np.float64)
            data[f"{o.name}.faces"] = np.asarray(mesh.faces, np.int64)
            data[f"{o.name}.uv"] = np.asarray(mesh.visual.uv, np.float64)
            if o.name == "rock":  # smooth-shaded in Mitsuba with these vertex normals
                data[f"{o.name}.normals"] = np.asarray(mesh.vertex_normals, np.float64)
            tex = np.asarray(texture_image(o.material.texture), np.float32)  # (h, w, 3), row 0 = top
            tex_path = Path(tmp) / f"{o.name}.exr"
            tex_path.write_bytes(sio.encode_exr(sio.pack_channels("", tex, ("R", "G", "B"))))
            data[f"{o.name}.texture_exr"] = np.array(str(tex_path))
        npz, exr = Path(tmp) / "scene.npz", Path(tmp) / "cycles.exr"
        np.savez(npz, **data)
        if args.keep:
            np.savez(Path(args.keep) / "scene.npz", **data)
        def cycles(npz_path):
            r = subprocess.run([str(py), str(HERE / "_cycles_render.py"), str(npz_path), str(exr)],
                               capture_output=True, text=True)
            line = next((ln for ln in r.stdout.splitlines() if ln.startswith("CYCLES_TIMES ")), None)
            if r.returncode != 0 or line is None:
                print(r.stdout[-3000:], r.stderr[-3000:])
                raise SystemExit(1)
            return json.loads(line.split(" ", 1)[1])

        if args.plan:  # Cycles' time at a quarter of the samples: its fixed and per-sample costs
            quarter = dict(data, settings=np.array([W, H, max(1, args.spp // 4), args.max_depth - 2, 2]))
            np.savez(Path(tmp) / "quarter.npz", **quarter)
            cq = cycles(Path(tmp) / "quarter.npz")
        cy = cycles(npz)
        # interleaved rounds, the machine's load drifting: Mitsuba render (best of 2), the whole
        # frame, Cycles (best of its 2 warm renders); ratios per round
        rounds = []
        for _ in range(args.rounds):
            m = min(_timed(lambda: render(5)) for _ in range(2))
            f = whole_frame(spec, built, view, args.spp, args.frames)
            rounds.append((m, f, cycles(npz)["warm_s"]))

        ch = sio.read_exr(exr)
        img_c = np.stack([ch["R"], ch["G"], ch["B"]], axis=-1).astype(np.float64)

    a, b, c = (np.asarray(x, np.float64) for x in (img_a, img_b, img_c))
    if args.keep:
        np.save(Path(args.keep) / "mitsuba.npy", a)
        np.save(Path(args.keep) / "cycles.npy", c)
    scale = np.mean(a)

    def rel_mad(x, y):
        return float(np.mean(np.abs(x - y)) / scale)

    print(f"Mitsuba {mi.variant()} vs Cycles {cy['version']}: {W}x{H}, {args.spp} spp, path depth "
          f"{args.max_depth} (Cycles bounces {args.max_depth - 2}), box filter, 2 threads, no denoising")
    print(f"  warm time: Mitsuba {mi_warm:.3f} s, Cycles {cy['warm_s']:.3f} s -> Cycles / Mitsuba = "
          f"{cy['warm_s'] / mi_warm:.2f} (cold: {mi_cold:.2f} s vs {cy['cold_s']:.2f} s) [{load()}]")
    print(f"  {args.rounds} interleaved rounds (Mitsuba render, whole frame: render, truth, encode, write, steady over"
          f" {args.frames} frames; Cycles): " + "; ".join(f"{m:.3f} / {f:.3f} / {c:.3f} s" for m, f, c in rounds))
    print("  " + target("Mitsuba render / Cycles", [m / c for m, f, c in rounds], 0.4))
    print("  " + target("Mitsuba whole frame / Cycles", [f / c for m, f, c in rounds], 0.4))
    print("  whole frame / render: " + ", ".join(f"{f / m:.2f}" for m, f, c in rounds))
    print(f"  mean image value: Mitsuba {np.mean(a):.4f}, Cycles {np.mean(c):.4f} (ratio {np.mean(c) / np.mean(a):.4f})")
    print(f"  relative MAD: Mitsuba seed vs seed {rel_mad(a, b):.4f}; Mitsuba vs Cycles {rel_mad(a, c):.4f}")
    blur = lambda x: x.reshape(H // 8, 8, W // 8, 8, 3).mean(axis=(1, 3))  # 8x8 means: noise averages out
    print(f"  8x8-block relative MAD (bias, not noise): seed vs seed {rel_mad(blur(a), blur(b)):.4f}; "
          f"Mitsuba vs Cycles {rel_mad(blur(a), blur(c)):.4f}")
    if args.plan:
        q = max(1, args.spp // 4)
        per_cy = (cy["warm_s"] - cq["warm_s"]) / (args.spp - q)
        print(f"  plan: Cycles {cq['warm_s']:.3f} s at {q} spp, {cy['warm_s']:.3f} s at {args.spp}: fixed"
              f" {cy['warm_s'] - per_cy * args.spp:.3f} s + {1e3 * per_cy:.1f} ms per sample per frame")
        for line in plan:
            print("  plan: " + line)
    return 0


def whole_frame(spec, built, view, spp: int, frames: int) -> float:
    """Steady seconds per frame of the pipeline on this scene: render_view_data, then the writer
    thread (truth checks, EXR/PNG, SHA-256, atomic writes, journal) overlapping the next frame."""
    from scenegen.dataset import DatasetWriter
    from scenegen.dataset.background import BackgroundWriter
    from scenegen.pipeline.view import render_view_data

    with tempfile.TemporaryDirectory() as tmp:
        w = DatasetWriter(Path(tmp) / "out", spec_sha256="0" * 64, seed=0, variant=built.variant, versions={})
        handed = []
        with BackgroundWriter(w) as bg:
            for i in range(frames + 1):
                image, linear, truth, extra = render_view_data(spec, built, i, view, spp=spp, seed=spec.render.seed)
                bg.submit(f"cam_{i:04d}", image=image, linear_rgb=linear, truth=truth, extra_files=extra)
                handed.append(time.perf_counter())
        w.close()
    return (handed[-1] - handed[0]) / frames


def _timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def _best(fn, n: int = 3) -> float:
    fn()
    times = []
    for _ in range(n):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def mitsuba_plan(spec, built, view, args, render) -> list[str]:
    """Where Mitsuba's time goes on this picture (each figure the best of three)."""
    import drjit as dr
    import mitsuba as mi

    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    def mi_render(b, sensor, spp):  # a sensor of ours: render_view sets its camera first
        if sensor is None:
            return lambda: render_view(b.device, "cam", view.cam_from_world, spp=spp, seed=5)
        return lambda: np.array(mi.render(b.scene, sensor=sensor, spp=spp, seed=5))

    out = []
    q = max(1, args.spp // 4)
    full = _best(lambda: render(5))
    quarter = _best(mi_render(built, None, q))
    per = (full - quarter) / (args.spp - q)
    out.append(f"Mitsuba {quarter:.3f} s at {q} spp, {full:.3f} s at {args.spp}: fixed {full - per * args.spp:.3f} s"
               f" + {1e3 * per:.1f} ms per sample per frame")
    W, H = args.size  # Mitsuba's built-in pinhole: fx = 0.9 W, principal point at the image centre
    fov = float(np.degrees(2 * np.arctan(W / (2 * 0.9 * W))))
    wfc = view.cam_from_world.inverse()
    eye, fwd, up = wfc.t, wfc.R[:, 2], -wfc.R[:, 1]
    persp = mi.load_dict({"type": "perspective", "fov": fov, "fov_axis": "x",
                          "to_world": mi.ScalarTransform4f().look_at(origin=eye.tolist(), target=(eye + fwd).tolist(),
                                                                     up=up.tolist()),
                          "film": {"type": "hdrfilm", "width": W, "height": H, "rfilter": {"type": "box"},
                                   "component_format": "float32"},
                          "sampler": {"type": "ldsampler", "sample_count": args.spp}})
    builtin = _best(mi_render(built, persp, args.spp))
    out.append(f"Mitsuba's built-in perspective sensor {builtin:.3f} s vs ours {full:.3f} s ({builtin / full:.2f})")
    direct = build_scene(spec, spp=args.spp, sampler="ldsampler", max_depth=2)
    t_direct = _best(mi_render(direct, None, args.spp))
    out.append(f"path depth 2 (direct light only) {t_direct:.3f} s vs depth {args.max_depth} {full:.3f} s"
               f" ({t_direct / full:.2f})")
    dr.set_thread_count(1)
    one = _best(lambda: render(5), n=1)
    dr.set_thread_count(2)
    out.append(f"1 thread {one:.3f} s vs 2 threads {full:.3f} s ({one / full:.2f} x)")
    indep = build_scene(spec, spp=args.spp, sampler="independent", max_depth=args.max_depth)
    t_indep = _best(mi_render(indep, None, args.spp))
    out.append(f"independent sampler {t_indep:.3f} s vs ldsampler {full:.3f} s ({t_indep / full:.2f}; 4x noisier,"
               " shared notes)")
    return out


if __name__ == "__main__":
    sys.exit(main())
