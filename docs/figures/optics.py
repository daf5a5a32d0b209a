"""Figure: the lens and time effects side by side (writes docs/figures/optics.png).

One small scene (a checkerboard, a textured blob, a ball) rendered with no effect, then with each
of thin-lens defocus, camera motion blur, a rolling shutter under a fast pan, lateral chromatic
aberration (exaggerated to be visible) and object motion blur. The truth of every panel is the
same pinhole, mid-exposure, green-channel truth (docs/image_formation.md).

    .venv/bin/python docs/figures/optics.py
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[2]

SCENE = """
name: optics_figure
render: {spp: 64, max_depth: 3}
objects:
  - name: floor
    shape: {type: plane, size: [4, 4]}
    material: {type: diffuse, color: 0.5}
  - name: board
    target: {type: checkerboard, inner_cols: 7, inner_rows: 5, square_m: 0.08}
    transform: {translation: [-0.35, 0.3, 0.3], rotation_deg: [70, 0, 0]}
  - name: rock
    shape: {type: blob, radius: 0.25, subdivisions: 4}
    transform: {translation: [0.35, 0.5, 0.25]}
    material: {type: diffuse, texture: {type: natural, params: {size_px: 256}}}
  - name: ball
    shape: {type: sphere, radius: 0.12}
    transform: {translation: [0.3, -0.2, 0.12]}
    material: {type: plastic, color: [0.7, 0.1, 0.05], roughness: 0.15}
    OBJMOTION
lights:
  - {type: area, size: [1.5, 1.5], position: [1.0, -1.5, 3.0], look_at: [0, 0, 0], radiance: 6}
  - {type: constant, radiance: 0.2}
cameras:
  cam:
    model: opencv
    size: [320, 240]
    fx: 300
    dist: [-0.1, 0.02, 0, 0]
    OPTICS
views:
  - camera: cam
    CAMMOTION
    look_at:
      - {eye: [0.0, -1.9, 1.1], target: [0.0, 0.2, 0.25]}
"""

PANELS = [
    ("clean", {}),
    ("defocus f/1.4, 24 mm, focus 0.5 m", {"OPTICS": "lens: {f_number: 1.4, focus_distance_m: 0.5, pixel_pitch_um: 80}"}),
    ("camera motion blur 20 ms", {"OPTICS": "shutter: {exposure_s: 0.02}",
                                  "CAMMOTION": "motion: {linear_velocity_mps: [1.0, 0, 0], angular_velocity_deg_s: [0, 10, 0]}"}),
    ("rolling shutter, 30 ms readout, fast pan", {"OPTICS": "shutter: {rolling_readout_s: 0.03}",
                                             "CAMMOTION": "motion: {angular_velocity_deg_s: [0, 250, 0]}"}),
    ("chromatic aberration (R x1.02, B x0.98)", {"OPTICS": "chromatic_aberration: {red_focal_scale: 1.02, blue_focal_scale: 0.98}"}),
    ("object motion blur (ball 4 m/s)", {"OPTICS": "shutter: {exposure_s: 0.02}",
                                         "OBJMOTION": "motion: {linear_velocity_mps: [4.0, 0, 0]}"}),
]


def render(text: str) -> np.ndarray:
    from scenegen.geometry.color import srgb_image as encode_image
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene
    from scenegen.spec import parse_spec, resolve_views

    spec = parse_spec(text, base_dir=ROOT / "scenes")
    view = resolve_views(spec)[0]
    built = build_scene(spec, spp=spec.render.spp, sampler=spec.render.sampler, max_depth=spec.render.max_depth)
    linear = render_view(built.device, view.camera, view.cam_from_world, spp=spec.render.spp, seed=1,
                         motion=view.motion)
    return encode_image(linear, 8)


def main() -> None:
    from scenegen.render.backend import load_mitsuba

    load_mitsuba("auto")
    tiles = []
    for title, subs in PANELS:
        text = SCENE
        for key in ("OPTICS", "CAMMOTION", "OBJMOTION"):
            text = text.replace(key, subs.get(key, ""))
        img = np.ascontiguousarray(render(text)[..., ::-1])
        cv2.rectangle(img, (0, 0), (319, 18), (255, 255, 255), -1)
        cv2.putText(img, title, (4, 13), cv2.FONT_HERSHEY_SIMPLEX, 0.42, (0, 0, 0), 1, cv2.LINE_AA)
        tiles.append(img)
    rows = [np.concatenate(tiles[i:i + 3], axis=1) for i in range(0, len(tiles), 3)]
    out = ROOT / "docs/figures/optics.png"
    cv2.imwrite(str(out), np.concatenate(rows, axis=0))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
