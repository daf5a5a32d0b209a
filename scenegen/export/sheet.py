"""Contact sheets: one row per view, the rendered image beside false-colour pictures of its
truth (depth, normals, ids), as one RGB image; and the HTML page that goes with it.

Pictures, not truth: each tile is resized (nearest neighbour for ids, area averaging for the
rest) to ``tile_width`` pixels. Colours:

* depth: ``depth_z`` mapped through OpenCV's TURBO colour map, near = red, far = blue, over the
  view's own [min, max] of valid depth (written in the row's caption), a span of at least
  ``MIN_DEPTH_SPAN`` of the far depth (a frontal plane stays one colour); black = no surface;
* normals: camera-frame unit normals as RGB = (n + 1) / 2 (x right = red, y down = green,
  z forward = blue); black = no surface;
* ids: one colour per instance id (a fixed hash, the same in every view); black = 0 (none).
"""
from __future__ import annotations

import html

import cv2
import numpy as np

from scenegen.dataset.truth import TruthKind
from scenegen.geometry.color import to_uint8

KINDS = ("image", "depth", "normals", "ids")
LABEL_PX = 18  # height of the text strip above each row
MIN_DEPTH_SPAN = 0.05  # smallest colour-map span, as a fraction of the far depth
GAP_PX = 2
MIN_TILE_WIDTH_PX = 16
#: Widest tile: four tiles side by side make a sheet at most 16,390 px wide, the image-side limit
#: of a spec (MAX_IMAGE_SIDE_PX, 16,384, docs/scene_spec.md 'Limits') give or take the gaps.
MAX_TILE_WIDTH_PX = 4096
#: Most pixels of one sheet: 2^28 (768 MB of RGB while it is composed and encoded; the default
#: 160 px tiles of 4:3 views fit 2,968 views). Checked before anything is rendered or read.
MAX_SHEET_PIXELS = 1 << 28


def check_tile_width(width: int) -> int:
    """``width`` if it is a tile width from MIN_TILE_WIDTH_PX to MAX_TILE_WIDTH_PX; ValueError
    naming ``--tile-width`` otherwise."""
    if not MIN_TILE_WIDTH_PX <= width <= MAX_TILE_WIDTH_PX:
        raise ValueError(f"--tile-width: expected {MIN_TILE_WIDTH_PX} to {MAX_TILE_WIDTH_PX:,} pixels (four tiles "
                         f"make a sheet row), got {width:,}")
    return width


def check_sheet_size(width: int, sizes) -> tuple[int, int]:
    """(width, height) in pixels of the sheet of views of ``sizes`` ((W, H) each) at tile ``width``,
    computed before any tile is made; ValueError when it exceeds MAX_SHEET_PIXELS."""
    sheet_w = len(KINDS) * width + GAP_PX * (len(KINDS) - 1)
    sheet_h = sum(LABEL_PX + max(1, round(h * width / w)) + GAP_PX for w, h in sizes)
    if sheet_w * sheet_h > MAX_SHEET_PIXELS:
        raise ValueError(f"--tile-width {width}: the contact sheet of {len(sizes):,} views would be {sheet_w:,} x "
                         f"{sheet_h:,} pixels, more than {MAX_SHEET_PIXELS:,}; give a smaller --tile-width")
    return sheet_w, sheet_h


def image_tile(image) -> np.ndarray:
    a = to_uint8(np.asarray(image))
    return np.repeat(a[..., None], 3, axis=2) if a.ndim == 2 else a


def depth_tile(depth_z, valid) -> tuple[np.ndarray, tuple[float, float] | None]:
    """(RGB uint8, (near, far) metres or None when nothing is valid)."""
    d = np.asarray(depth_z, np.float64)
    ok = np.asarray(valid, bool) & np.isfinite(d)
    if not ok.any():
        return np.zeros(d.shape + (3,), np.uint8), None
    lo, hi = float(d[ok].min()), float(d[ok].max())
    t = np.zeros(d.shape)
    span = max(hi - lo, MIN_DEPTH_SPAN * abs(hi))
    t[ok] = (d[ok] - lo) / span if span > 0 else 0.0
    bgr = cv2.applyColorMap(np.rint(255 * (1 - t)).astype(np.uint8), cv2.COLORMAP_TURBO)
    rgb = bgr[..., ::-1].copy()
    rgb[~ok] = 0
    return rgb, (lo, hi)


def normals_tile(normals_cam, valid) -> np.ndarray:
    n = np.nan_to_num(np.asarray(normals_cam, np.float64))
    rgb = np.rint(np.clip((n + 1) / 2, 0, 1) * 255).astype(np.uint8)
    rgb[~np.asarray(valid, bool)] = 0
    return rgb


def id_colours(ids) -> np.ndarray:
    """(..., 3) uint8 colour of each id: a fixed integer hash; 0 is black."""
    x = np.asarray(ids, np.uint64)
    h = (x * np.uint64(2654435761)) & np.uint64(0xFFFFFFFF)
    rgb = np.stack([(h >> np.uint64(s)) & np.uint64(0xFF) for s in (0, 8, 16)], -1).astype(np.uint8)
    rgb = (64 + (rgb.astype(np.uint16) * 191) // 255).astype(np.uint8)  # never near black
    rgb[x == 0] = 0
    return rgb


def resized(tile: np.ndarray, width: int, nearest: bool = False) -> np.ndarray:
    h, w = tile.shape[:2]
    height = max(1, round(h * width / w))
    return cv2.resize(tile, (width, height), interpolation=cv2.INTER_NEAREST if nearest else cv2.INTER_AREA)


def view_tiles(image, truth: dict, width: int) -> tuple[list[np.ndarray], str]:
    """The four tiles of a view (KINDS order) at ``width`` pixels, and the row's caption extra."""
    valid = np.asarray(truth[TruthKind.VALID], bool)
    depth, rng = depth_tile(truth[TruthKind.DEPTH_Z], valid)
    tiles = [resized(image_tile(image), width), resized(depth, width),
             resized(normals_tile(truth[TruthKind.NORMALS_CAM], valid), width),
             resized(id_colours(truth[TruthKind.INSTANCE_ID]), width, nearest=True)]
    ids = np.unique(np.asarray(truth[TruthKind.INSTANCE_ID])[valid])
    extra = (f"depth {rng[0]:.3g}-{rng[1]:.3g} m, " if rng else "no surface, ") + f"{len(ids)} instances"
    return tiles, extra


def compose(rows: list[tuple[str, list[np.ndarray]]]) -> np.ndarray:
    """One RGB uint8 image: per row a text strip (its caption) over its tiles side by side."""
    if not rows:
        raise ValueError("a contact sheet needs at least one view")
    width = sum(t.shape[1] for t in rows[0][1]) + GAP_PX * (len(rows[0][1]) - 1)
    blocks = []
    for caption, tiles in rows:
        h = max(t.shape[0] for t in tiles)
        strip = np.full((LABEL_PX, width, 3), 255, np.uint8)
        cv2.putText(strip, caption.encode("ascii", "replace").decode(), (3, LABEL_PX - 5),
                    cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 1, cv2.LINE_AA)
        body = np.full((h, width, 3), 255, np.uint8)
        x = 0
        for t in tiles:
            body[: t.shape[0], x: x + t.shape[1]] = t
            x += t.shape[1] + GAP_PX
        blocks += [strip, body, np.full((GAP_PX, width, 3), 255, np.uint8)]
    return np.concatenate(blocks, axis=0)


def html_page(title: str, png_name: str, rows: list[dict]) -> str:
    """A self-contained page: the sheet and a table of the views (every text escaped)."""
    esc = html.escape
    head = "".join(f"<th>{esc(k)}</th>" for k in ("view", "camera", "size", "truth"))
    body = "".join("<tr>" + "".join(f"<td>{esc(str(r[k]))}</td>" for k in ("view", "camera", "size", "truth"))
                   + "</tr>" for r in rows)
    legend = ("Columns: image; depth (TURBO, near red, far blue, black = no surface); camera-frame "
              "normals as (n + 1) / 2; instance ids (one colour each, black = none).")
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>{esc(title)}</title>"
            "<style>body{font-family:sans-serif;margin:1em}table{border-collapse:collapse}"
            "td,th{border:1px solid #ccc;padding:2px 6px;font-size:13px}img{max-width:100%}</style></head>"
            f"<body><h1>{esc(title)}</h1><p>{esc(legend)}</p>"
            f"<p><img src='{esc(png_name, quote=True)}' alt='contact sheet'></p>"
            f"<table><tr>{head}</tr>{body}</table></body></html>\n")
