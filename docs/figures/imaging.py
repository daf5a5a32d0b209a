"""Figure: the clean render beside each photometric effect (writes docs/figures/imaging.png).

Renders the first view of scenes/degraded_camera.yaml once (Mitsuba), then runs the imaging
chain with one effect switched on at a time, and all together. Each panel shows the whole image
and, below it, a 4x enlarged crop (centre-left) where noise and demosaicing are visible.

    .venv/bin/python docs/figures/imaging.py
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import numpy as np

from scenegen.imaging import apply_chain, seeds
from scenegen.imaging.noise import SensorParams
from scenegen.imaging.vignetting import VignettingParams
from scenegen.geometry.color import srgb_image as encode_image
from scenegen.pipeline.view import view_seed
from scenegen.spec import load_spec, resolve_views

ROOT = Path(__file__).resolve().parents[2]
CROP = (slice(150, 210), slice(60, 140))  # rows, cols of the enlarged crop
ZOOM = 4


def render_linear(spec, view):
    from scenegen.render.backend import load_mitsuba

    load_mitsuba(spec.render.variant)
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    built = build_scene(spec, spp=spec.render.spp, sampler=spec.render.sampler,
                        max_depth=spec.render.max_depth)
    return render_view(built.device, view.camera, view.cam_from_world, spp=spec.render.spp,
                       seed=view_seed(spec.render.seed, 0)), built.cameras[view.camera]


def variants(p):
    """(label, params): one effect at a time on top of exposure, then the full chain."""
    quiet = dataclasses.replace(p.sensor, temporal_noise=False, prnu_percent=0.0, dsnu_e=0.0,
                                dark_current_e_per_s=0.0)
    base = dataclasses.replace(p, vignetting=VignettingParams(), sensor=quiet, bayer=None)
    return [
        ("exposure + sRGB", base),
        ("+ vignetting", dataclasses.replace(base, vignetting=p.vignetting)),
        ("+ sensor noise", dataclasses.replace(base, sensor=p.sensor)),
        ("+ Bayer / demosaic", dataclasses.replace(base, bayer=p.bayer)),
        ("full chain", p),
    ]


def panel(img8: np.ndarray, label: str) -> np.ndarray:
    crop = cv2.resize(img8[CROP], None, fx=ZOOM, fy=ZOOM, interpolation=cv2.INTER_NEAREST)
    full = cv2.resize(img8, (crop.shape[1], crop.shape[1] * img8.shape[0] // img8.shape[1]),
                      interpolation=cv2.INTER_AREA)
    x0, y0 = CROP[1].start * full.shape[1] // img8.shape[1], CROP[0].start * full.shape[0] // img8.shape[0]
    x1, y1 = CROP[1].stop * full.shape[1] // img8.shape[1], CROP[0].stop * full.shape[0] // img8.shape[0]
    full = full.copy()
    cv2.rectangle(full, (x0, y0), (x1, y1), (255, 255, 0), 1)
    head = np.full((28, crop.shape[1], 3), 255, np.uint8)
    cv2.putText(head, label, (6, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (0, 0, 0), 1, cv2.LINE_AA)
    return np.vstack([head, full, crop])


def main():
    spec = load_spec(ROOT / "scenes/degraded_camera.yaml")
    view = resolve_views(spec)[0]
    params = spec.cameras[view.camera].imaging
    linear, camera = render_linear(spec, view)
    tiles = [panel(encode_image(linear, 8), "clean (render)")]
    for label, p in variants(params):
        tiles.append(panel(apply_chain(linear, p, camera, seeds.frame_seed(spec.seed, 0)).image,
                           label))
    gap = np.full((tiles[0].shape[0], 6, 3), 255, np.uint8)
    row = np.hstack([t for tile in tiles for t in (tile, gap)][:-1])
    out = ROOT / "docs/figures/imaging.png"
    cv2.imwrite(str(out), row[..., ::-1])
    print(f"wrote {out} ({row.shape[1]}x{row.shape[0]})")


if __name__ == "__main__":
    main()
