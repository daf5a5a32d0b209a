"""``scenegen gallery DATASET``: the contact sheet of a rendered dataset (:mod:`.sheet`) as one
PNG and an HTML page next to it (view names, cameras and truth summaries, all text escaped)."""
from __future__ import annotations

from pathlib import Path

from scenegen.dataset.codecs import encode_png
from scenegen.dataset.files import atomic_write_bytes
from scenegen.export.common import each, open_dataset
from scenegen.export.sheet import check_sheet_size, check_tile_width, compose, html_page, view_tiles


def default_png(out_dir) -> Path:
    p = Path(out_dir)
    return p.parent / f"{p.name}.gallery.png"


def gallery(out_dir, png=None, *, max_width: int = 160, progress=None) -> dict:
    """Write the gallery of dataset ``out_dir``: ``png`` (default ``<OUT>.gallery.png`` next to
    the dataset) and the same name with ``.html``; returns {png, html, views}."""
    check_tile_width(max_width)
    ds = open_dataset(out_dir)
    check_sheet_size(max_width, [(c.width, c.height) for c in (ds.camera(v)[0] for v in ds.views)])
    png = Path(png) if png is not None else default_png(out_dir)
    rows, table = [], []
    for v in each(ds.views, progress):
        cam, _ = ds.camera(v)
        tiles, extra = view_tiles(ds.image(v), ds.truth(v), max_width)
        rows.append((f"{v}: {extra}", tiles))
        table.append({"view": v, "camera": f"{ds.view_info(v).get('camera_name')} ({cam.model})",
                      "size": f"{cam.width}x{cam.height}", "truth": extra})
    atomic_write_bytes(png, encode_png(compose(rows)))
    page = png.with_suffix(".html")
    atomic_write_bytes(page, html_page(f"{ds.scene_name}: {Path(out_dir).name}", png.name, table).encode())
    return {"png": str(png), "html": str(page), "views": len(rows)}
