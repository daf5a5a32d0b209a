"""``scenegen preview SPEC``: a fast look at every view of a spec before a full render: each
camera scaled down to the tile width, rendered at low spp, with its truth cast, composed into
one contact sheet PNG (:mod:`scenegen.export.sheet`); nothing else is written.

The scaled camera keeps the field of view: ``W' = tile width``, ``s = W' / W``, ``H' =
round(H s)``, fx, fy scaled by W'/W and H'/H, the principal point scaled about the pixel edge
(OpenCV centres: ``cx' = (cx + 0.5) s - 0.5``), distortion unchanged (it acts on normalised
coordinates). The imaging chain and the lens and time effects are kept; they act on the smaller
image (noise and blur are per pixel), so a preview is a picture of the framing and the truth,
not of the final image quality.
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from scenegen.dataset.codecs import encode_png
from scenegen.dataset.files import atomic_write_bytes
from scenegen.export.sheet import check_sheet_size, check_tile_width, compose, view_tiles
from scenegen.geometry.conventions import rescaled_opencv_pixels
from scenegen.pipeline.progress import ViewProgress
from scenegen.pipeline.view import render_view_data
from scenegen.render import load_scene
from scenegen.spec import load_spec, resolve_views
from scenegen.spec.model import RenderSettings
from scenegen.spec.parse.read import option_in_range


def scaled_camera(cam, width: int):
    """The CameraSpec ``cam`` at ``width`` pixels (module docstring); unchanged when not smaller."""
    if width >= cam.width:
        return cam
    height = max(1, round(cam.height * width / cam.width))
    sx, sy = width / cam.width, height / cam.height
    cx, cy = rescaled_opencv_pixels((cam.cx, cam.cy), (sx, sy))
    return dataclasses.replace(cam, width=width, height=height, fx=cam.fx * sx, fy=cam.fy * sy,
                               cx=float(cx), cy=float(cy), skew=cam.skew * sx, fov_deg=None)


def default_png(spec_path) -> Path:
    p = Path(spec_path)
    return p.with_name(f"{p.stem}.preview.png")


def preview(spec_path, png=None, *, spp: int = 4, max_width: int = 160, variant: str | None = None,
            progress: bool = True) -> dict:
    """Render the contact sheet of every view of ``spec_path`` into ``png`` (default
    ``<spec>.preview.png``); returns {png, views, spp, seconds}."""
    option_in_range(RenderSettings, "spp", spp, "--spp")
    check_tile_width(max_width)
    t0 = time.perf_counter()
    spec = load_spec(spec_path)
    small = dataclasses.replace(spec, cameras={k: scaled_camera(c, max_width) for k, c in spec.cameras.items()})
    views = resolve_views(small)
    check_sheet_size(max_width, [(small.cameras[v.camera].width, small.cameras[v.camera].height) for v in views])
    built = load_scene(small, variant=variant or small.render.variant, spp=spp)
    rows = []
    with ViewProgress(progress, len(views), label="preview") as bar:
        for index, v in enumerate(views):
            image, _, truth, _ = render_view_data(small, built, index, v, spp=spp, seed=small.render.seed,
                                                  all_patterns=False)
            tiles, extra = view_tiles(image, truth, max_width)
            rows.append((f"{v.name}: {extra}", tiles))
            bar.advance()
    png = Path(png) if png is not None else default_png(spec_path)
    atomic_write_bytes(png, encode_png(compose(rows)))
    return {"png": str(png), "views": len(rows), "spp": spp, "seconds": time.perf_counter() - t0}
