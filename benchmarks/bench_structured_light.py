"""A structured-light view vs one plain camera frame (not a test): a 10-pattern Gray sequence
(a 1024x768 projector's 10 column bits, no inverses or references) at 640x480 and 16 spp, the
desktop-scanner scene (scenes/sl_desktop_scanner.yaml, static), each as a frame of a serial run
makes it (``render_view_data``: the renders, the truth pass, the imaging chain, and for the lit
view its pattern files and projector truth, encoded). The plain frame is the same camera in the
same scene without the projector. Runs interleaved (plain, lit, plain, ...), ratios per round.

Run: .venv/bin/python benchmarks/bench_structured_light.py [--reps 3] [--spp 16]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, fmt, interleaved, load, ratios, timed  # noqa: E402

PROJECTOR = """
projectors:
  proj:
    intrinsics: {model: opencv, size: [1024, 768], fx: 1320, cx: 511.2, cy: 601.6, skew: 0.3,
                 dist: [-0.06, 0.02, 0.0004, -0.0003, 0.0]}
    intensity_w_sr: 0.6
    patterns: gray
    pattern_axes: columns
    pattern_inverse: false
    pattern_white_black: false
"""


def scene_text(lit: bool) -> str:
    """The scanner scene, static (no turntable motion), at 640x480; with or without the projector."""
    text = (ROOT / "scenes/sl_desktop_scanner.yaml").read_text()
    head, rest = text.split("\nobjects:", 1)
    head = head.split("\nsequence:")[0]
    objects, rest = rest.split("\nlights:", 1)
    objects = objects.split("    joint:")[0]  # the object's joint is its last key
    # without the clock the object sits on the turntable in the world frame
    objects = objects.replace("    parent: turntable\n", "").replace("translation: [0, 0, 0.07]", "translation: [0, 0, 0.08]")
    lights, rest = rest.split("\ncameras:", 1)
    cameras = ("\ncameras:\n  cam: {model: opencv, size: [640, 480], fx: 1040, fy: 1042, cx: 317.9, cy: 243.3,"
               " dist: [-0.1, 0.04, 0.0003, -0.0002, 0.0]}\n")
    member = ("      - {kind: projector, sensor: proj, name: proj,\n"
              "         rig_from_sensor: {translation: [0.15, 0.0, 0.0], rotation_deg: [-9, -15, 0]}}\n")
    rig = "rigs:\n  scanner:\n    type: multi\n    members:\n      - {camera: cam}\n" + (member if lit else "")
    views = "views:\n  - rig: scanner\n    look_at: [{eye: [0.0, -0.5, 0.2], target: [0.0, 0.0, 0.06]}]\n"
    return (head + "\nobjects:" + objects + "\nlights:" + lights + cameras + (PROJECTOR if lit else "") + rig
            + views)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--spp", type=int, default=16)
    args = ap.parse_args(argv)

    from scenegen.pipeline.view import render_view_data
    from scenegen.render import load_scene
    from scenegen.spec import parse_spec, resolve_views

    frames = {}
    for name, lit in (("plain", False), ("lit", True)):
        spec = parse_spec(scene_text(lit), file=f"{name}.yaml", base_dir=ROOT / "scenes")
        built = load_scene(spec, spp=args.spp)
        view = resolve_views(spec)[0]
        frames[name] = (lambda spec=spec, built=built, view=view:
                        render_view_data(spec, built, 0, view, spp=args.spp, seed=spec.render.seed))
        frames[name]()  # compile the kernels once
    lit_spec = parse_spec(scene_text(True), file="lit.yaml", base_dir=ROOT / "scenes")
    n = len(lit_spec.sensors["projector"]["proj"].pattern_sequence().frames)
    runs = interleaved({k: (lambda f=f: timed(f)) for k, f in frames.items()}, args.reps)
    print(f"640x480, {args.spp} spp, {n} patterns [{load()}]")
    print(f"plain camera frame:      {fmt(runs['plain'], ' s')}")
    print(f"{n}-pattern Gray view:    {fmt(runs['lit'], ' s')}")
    print(f"ratio lit / plain:       {fmt(ratios(runs['lit'], runs['plain']), 'x')} (the renders alone: {n}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
