"""Truth across time for a pair of 640x480 frames with moving objects, as a ratio of the truth
pass (not a test; issue 16).

Scene: scenes/moving_table.yaml with its camera at 640x480 (fx doubled): a sliding and turning
crate, a rolling ball, a spinning torus, a box that appears. Frames 0 and 3 (the pair of the
scene's flow step 3). Timed, interleaved per round:

* ``truth``: one truth pass of a frame as the dataset stores it (the scene moved to its time);
* ``pair``: the motion truth of the pair both ways (a -> b and b -> a: every pixel's surface
  point moved with its object's poses, projected by the other camera, its visibility cast in
  the other frame's scene, flow and scene flow), from the two frames' float64 truth points,
  which are recomputed in the round (two truth passes included, as the sequence stage does);
* ``pair_cached``: the same with the frames' truth points already at hand;
* ``static``: the static cross-view correspondences of the same two views both ways
  (:meth:`scenegen.render.scene.LoadedScene.correspond`, the scene left where it is): what the
  pair would cost if nothing moved.

The issue sets no bound. Printed: what moving objects add, pair_cached / static (the points moved
per object, and the scene's geometry moved to the other frame's time: Mitsuba rebuilds its BVH;
since the static correspondences became one kernel this ratio is mostly those rebuilds), and as a
``TARGET`` line the whole pair as a ratio of the truth pass, <= 14 (set when a static direction
cost 3.5 truth passes; docs/performance.md).

Run: .venv/bin/python benchmarks/bench_flow.py [--reps 5]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, interleaved, load, ratios, target


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args(argv)

    from scenegen.pipeline.sequence import SequenceTruth
    from scenegen.pipeline.view import correspond_points, view_truth
    from scenegen.render import load_scene
    from scenegen.spec import parse_spec, resolve_views

    text = (ROOT / "scenes/moving_table.yaml").read_text()
    text = text.replace("size: [320, 240], fx: 300, fy: 300", "size: [640, 480], fx: 600, fy: 600")
    assert "640, 480" in text
    spec = parse_spec(text, file=str(ROOT / "scenes/moving_table.yaml"))
    views = resolve_views(spec)
    a, b = views[0], views[3]
    built = load_scene(spec, spp=1)

    def truth():
        t = time.perf_counter()
        view_truth(built, a, as_stored=True)
        return time.perf_counter() - t

    def pair(cached: bool):
        st = SequenceTruth(spec, built)
        if cached:
            st.frame(a), st.frame(b)
        t = time.perf_counter()
        m_ab, m_ba = st.motion(a, b), st.motion(b, a)
        m_ab.flow, m_ba.flow
        return time.perf_counter() - t

    st0 = SequenceTruth(spec, built)
    pa, pb = st0.frame(a)[0], st0.frame(b)[0]

    def static():
        t = time.perf_counter()
        for P, v in ((pa, b), (pb, a)):
            correspond_points(built, P, built.cameras[v.camera], v.cam_from_world)
        return time.perf_counter() - t

    truth(), pair(False), static()  # warm: kernels, first-use costs
    r = interleaved({"truth": truth, "pair": lambda: pair(False), "pair_cached": lambda: pair(True),
                     "static": static}, args.reps)
    print(f"moving_table 640x480, frames {a.name} and {b.name}, {load()}")
    print(f"  truth pass {fmt(r['truth'], ' ms', 1e3, 1)}; pair both ways {fmt(r['pair'], ' ms', 1e3, 1)};"
          f" pair, truth points cached {fmt(r['pair_cached'], ' ms', 1e3, 1)}")
    print(f"  static correspondences both ways {fmt(r['static'], ' ms', 1e3, 1)}")
    print(f"  pair (cached points) / truth: {fmt(ratios(r['pair_cached'], r['truth']))}")
    print(f"  flow pair (points cached) / static pair: {fmt(ratios(r['pair_cached'], r['static']))}")
    print("  " + target("flow pair / truth pass, 640x480 moving objects", ratios(r["pair"], r["truth"]), 14.0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
