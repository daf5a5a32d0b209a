"""LiDAR sweep cost (not a test): one 64-channel, 2048-column sweep (the Ouster OS1-64 preset in
scenes/lidar_street.yaml's street, 131,072 beams, each cast at its own time with the four moving
objects where they are then) against raw Mitsuba ray casting of the same rays:

* ``sweep``: :func:`scenegen.spec.sensors.lidar_sweep.sweep_fields` (poses at every beam's time,
  the cast, returns, noise, the stream's fields in numpy);
* ``raw``: the same world-frame rays (float32 numpy, precomputed) uploaded, intersected with
  ``scene.ray_intersect_preliminary`` in the loaded scene at the sweep's start (one static picture,
  as CARLA casts a step) and the distances brought back: the floor of any cast of these rays;
* ``raw_timed``: the same rays with their times through the timed scenes (the still world and
  one scene per moving object, :func:`scenegen.render.timed.timed_first_hit`) with the rays and
  the movers' poses at the 2048 column times precomputed: what casting each beam at its own time
  costs in Mitsuba alone.

Run: .venv/bin/python benchmarks/bench_lidar.py [--reps 5]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, interleaved, load, ratios, target, timed  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)
    from scenegen.render import load_scene
    from scenegen.spec import parse_spec
    from scenegen.spec.sensors.lidar_sweep import sweep_fields
    from scenegen.spec.sensors.lidar import lidar_trajectory
    from scenegen.spec.sensors.kind import SensorRun
    from scenegen.spec.views import rig_frames

    text = (ROOT / "scenes/lidar_street.yaml").read_text().replace("preset: velodyne_vlp16", "preset: ouster_os1_64")
    spec = parse_spec(text, file=str(ROOT / "scenes/lidar_street.yaml"), base_dir=ROOT / "scenes")
    scene = load_scene(spec, variant="llvm_ad_rgb", spp=1)
    import drjit as dr  # after load_scene: the backend picks the libLLVM before the first import
    import mitsuba as mi

    from scenegen.render.arrays import to_jit
    from scenegen.render.timed import timed_first_hit, upload_moves
    lidar = spec.sensors["lidar"]["vlp16"]
    pattern = lidar.scan_pattern()
    _, frames = rig_frames(spec)[0]
    member = spec.rigs["car"].members[1]
    run = SensorRun(spec=spec, member=member, sensor=lidar, frames=frames, stream="drive_lidar", writer=None)
    traj = lidar_trajectory(run, frames[0])
    times = (frames[0].time_s + pattern.beam_time_s).reshape(-1)
    R, t = traj.poses_at(times)
    d = np.einsum("nij,nj->ni", R, pattern.directions().reshape(-1, 3))
    o32, d32 = t.astype(np.float32), d.astype(np.float32)
    print(f"{len(times):,} beams ({pattern.shape[0]} columns x {pattern.shape[1]} channels), "
          f"{len(scene.description.movers)} moving objects")

    def sweep():
        sweep_fields(scene.cast_beams, lidar, pattern, traj, frames[0].time_s, noise_key=(1, "b", 0))

    def raw():
        scene.device.place_at(frames[0].time_s)
        ray = mi.Ray3f(mi.Point3f(*[to_jit(mi.Float, o32[:, i], np.float32) for i in range(3)]),
                       mi.Vector3f(*[to_jit(mi.Float, d32[:, i], np.float32) for i in range(3)]))
        si = scene.scene.ray_intersect_preliminary(ray, coherent=False)
        dist = dr.select(si.is_valid(), si.t, dr.inf)
        dr.eval(dist)
        return dist.numpy()

    ts = scene.timed()
    vec = lambda a: mi.Vector3d(*[to_jit(mi.Float64, np.ascontiguousarray(a[:, i]), np.float64)  # noqa: E731
                                  for i in range(3)])

    unique_times, at = np.unique(times, return_inverse=True)
    moves = scene.timeline.object_moves_at_times(unique_times)
    index = at.astype(np.uint32)

    def raw_timed():
        moves_jit = upload_moves(ts, moves, to_jit(mi.UInt32, index, np.uint32))
        dist, hit, *_ = timed_first_hit(ts, vec(t), vec(d), moves_jit, False, coherent=False)
        dist = dr.select(hit, dist, dr.inf)
        dr.eval(dist)
        return dist.numpy()

    for f in (sweep, raw, raw_timed):  # compile once
        f()
    res = interleaved({"sweep": lambda: timed(sweep), "raw": lambda: timed(raw),
                       "raw_timed": lambda: timed(raw_timed)}, args.reps)
    for k, v in res.items():
        print(f"{k}: {fmt(v, ' ms', 1e3, 1)}")
    print(f"sweep / raw (one static picture): {fmt(ratios(res['sweep'], res['raw']))}")
    print(f"raw_timed / raw: {fmt(ratios(res['raw_timed'], res['raw']))}")
    print(target("lidar sweep / raw Mitsuba cast of the same rays at their times", ratios(res["sweep"], res["raw_timed"]),
                 1.3))
    print(f"[{load()}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
