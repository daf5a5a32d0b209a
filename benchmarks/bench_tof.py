"""A ToF frame as a ratio of a camera frame at equal spp (issue 30): scenes/tof_room.yaml with its
ToF camera enlarged to 320 x 256, the camera frame rendered by Mitsuba's path tracer through our
sensor (spp 16, the scene's max_depth 3) against the ToF camera's path sums at 16 rays a pixel and
3 vertices a path (two frequencies), and against a whole ToF frame (path sums, truth pass, noise,
decoding, truth errors). Interleaved rounds after one warm-up each.

Run: .venv/bin/python benchmarks/bench_tof.py [--repeat 5] [--spp 16]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, interleaved, load, ratios, timed  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--spp", type=int, default=16)
    args = ap.parse_args(argv)

    from scenegen.render.backend import load_mitsuba

    mi = load_mitsuba("auto")
    import drjit as dr

    from scenegen.render.scene import build_scene
    from scenegen.spec import parse_spec, resolve_views
    from scenegen.spec.sensors.tof import tof_frame

    text = (ROOT / "scenes/tof_room.yaml").read_text()
    text = text.replace("ir: {size: [80, 64], fx: 56}", "ir: {size: [320, 256], fx: 224}")
    assert "320, 256" in text
    spec = parse_spec(text, file="tof_room.yaml", base_dir=ROOT / "scenes")
    built = build_scene(spec, spp=args.spp, sampler=spec.render.sampler, max_depth=spec.render.max_depth)
    tof = spec.sensors["tof"]["kinect_depth"]
    camera = built.cameras["ir"]
    pose = resolve_views(spec)[0].cam_from_world
    print(f"variant {mi.variant()}, {dr.thread_count()} threads, {load()}; {camera.width}x{camera.height}, "
          f"spp {args.spp}, max_depth / max_bounces {spec.render.max_depth} / {tof.max_bounces}, "
          f"{len(tof.freqs_hz)} frequencies")

    def camera_frame():
        return timed(lambda: built.render("ir", pose, spp=args.spp, seed=0))

    def tof_sums():
        return timed(lambda: built.tof(camera, pose, tof.freqs_hz, spp=args.spp, seed=0, max_bounces=tof.max_bounces))

    def tof_whole():
        import dataclasses
        t = dataclasses.replace(tof, spp=args.spp)
        return timed(lambda: tof_frame(built, t, pose, None, 0))

    for f in (camera_frame, tof_sums, tof_whole):
        f()  # warm: kernels compiled
    r = interleaved({"camera": camera_frame, "tof_sums": tof_sums, "tof_frame": tof_whole}, args.repeat)
    print(f"camera frame (Mitsuba path tracer): {fmt(r['camera'], ' s')}")
    print(f"ToF path sums:                      {fmt(r['tof_sums'], ' s')}")
    print(f"ToF frame (sums, truth, noise, decoding): {fmt(r['tof_frame'], ' s')}")
    print(f"ratio ToF path sums / camera frame: {fmt(ratios(r['tof_sums'], r['camera']), 'x')}")
    print(f"ratio ToF frame / camera frame:     {fmt(ratios(r['tof_frame'], r['camera']), 'x')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
