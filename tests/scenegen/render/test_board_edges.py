"""Detector-free check of a rendered ChArUco board: the markers' edges, located on the linear render
by strip sums, land on the stored marker corners.

The film's box filter makes each pixel the mean radiance over its square, and the board's bilinear
texture lookup turns a black/white texel edge into a ramp symmetric about the texel boundary. So
along an image row crossing a vertical edge (fronto-parallel board, edges along the pixel axes),
the sum of the pixels over a strip that starts and ends on flat paper equals the sum of a sharp
step at the edge: ``S = white (e - a) + black (b - e)`` over the strip [a, b] gives the edge
position ``e`` exactly, up to the render's Monte-Carlo noise (averaged over the edge's rows).
"""
from __future__ import annotations

import numpy as np
import pytest

from scenegen.spec import parse_spec, resolve_views

# The bound: edge-fit corners within 0.05 px of the stored ones (the ArUco grid measured
# 0.028 px median before any fix; the ChArUco board with 12.5 px marker offsets 0.24 px median).
EDGE_FIT_TOL_PX = 0.05
STRIP_HALF_PX = 4  # pixels on each side of the edge summed per row (inside the flat paper and border)
CORNER_CLEAR_PX = 3  # rows/columns this close to a marker corner are left out

# The board: 6 x 5 squares of 4 cm, 3 cm DICT_6X6_50 markers, 0.5 cm from their square's
# edges (12.5 texels at 100 texels per square; 13 at the 104 the resolution rule chooses).
SPEC = """
name: charuco_edges
render: {spp: 256, max_depth: 2, sampler: ldsampler}
objects:
  - name: board
    target: {type: charuco, squares_x: 6, squares_y: 5, square_m: 0.04, marker_m: 0.03,
             dictionary: DICT_6X6_50}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam: {size: [800, 680], fx: 910.0, fy: 910.0, cx: 399.63, cy: 339.27}
views:
  - camera: cam
    look_at: [{eye: [0.0013, -0.0021, 0.3], target: [0.0013, -0.0021, 0.0], up: [0, -1, 0]}]
"""


def _edge(img, rows, cols, dark_first: bool, white: float, black: float) -> float:
    """Edge position along the strip's axis (OpenCV pixel coordinates) from strip sums: ``img``
    indexed [rows, cols] with the strip along the last axis, pixels ``cols`` (consecutive)."""
    a, b = cols[0] - 0.5, cols[-1] + 0.5
    S = img[np.ix_(rows, cols)].sum(axis=1)
    lo, hi = (black, white) if dark_first else (white, black)
    e = (S + lo * a - hi * b) / (lo - hi)  # S = lo (e - a) + hi (b - e)
    return float(np.mean(e))


def edge_fit_marker_corners(img, truth, white: float, black: float) -> np.ndarray:
    """(4, 2) corners of one black marker on white paper in a fronto-parallel, axis-aligned linear
    grey image, each the crossing of two fitted edges, in the order of ``truth`` (4, 2), which says
    only where to look (the strips are placed around it on whole pixels)."""
    (x0, y0), (x1, y1) = truth.min(axis=0), truth.max(axis=0)
    rows = np.arange(int(np.ceil(y0 + CORNER_CLEAR_PX)), int(np.floor(y1 - CORNER_CLEAR_PX)) + 1)
    cols = np.arange(int(np.ceil(x0 + CORNER_CLEAR_PX)), int(np.floor(x1 - CORNER_CLEAR_PX)) + 1)
    strip = lambda c: np.arange(int(round(c)) - STRIP_HALF_PX, int(round(c)) + STRIP_HALF_PX + 1)  # noqa: E731
    left = _edge(img, rows, strip(x0), False, white, black)
    right = _edge(img, rows, strip(x1), True, white, black)
    top = _edge(img.T, cols, strip(y0), False, white, black)
    bottom = _edge(img.T, cols, strip(y1), True, white, black)
    centre = truth.mean(axis=0)
    return np.array([[left if x < centre[0] else right, top if y < centre[1] else bottom] for x, y in truth])


def fit_board(spec_text: str, spp: int = 256):
    """(edge-fit corners (M, 4, 2), stored corners projected (M, 4, 2)) of the board's markers."""
    from scenegen.render import load_scene
    from scenegen.render.materials import BOARD_BLACK, BOARD_WHITE

    spec = parse_spec(spec_text)
    scene = load_scene(spec, variant="llvm_ad_rgb", spp=spp)
    board, world_from_board = scene.boards["board"]
    view = resolve_views(spec)[0]
    cam = scene.cameras["cam"]
    img = scene.render("cam", view.cam_from_world, spp=spp, seed=3).mean(axis=2).astype(np.float64)
    truth = cam.project(view.cam_from_world.apply(world_from_board.apply(
        board.marker_corners_board.reshape(-1, 3)))).reshape(-1, 4, 2)
    # constant radiance 1 on a diffuse print: radiance = reflectance (checked on the flat paper)
    white, black = BOARD_WHITE, BOARD_BLACK
    fits = np.stack([edge_fit_marker_corners(img, t, white, black) for t in truth])
    return fits, truth, img


@pytest.mark.render
def test_edge_fit_of_rendered_charuco_markers_lands_on_the_stored_corners():
    fits, truth, img = fit_board(SPEC)
    paper = img[5:25, 5:25]  # the board's white margin
    assert abs(np.median(paper) - 0.85) < 0.01
    err = np.linalg.norm(fits - truth, axis=2)
    print(f"edge fit vs stored marker corners: median {np.median(err):.4f} px, max {err.max():.4f} px "
          f"over {err.size} corners")
    assert np.max(err) < EDGE_FIT_TOL_PX, (np.median(err), np.max(err))
    # no bias either: a half-texel shift (1.17 px per texel here) would be 0.58 px
    assert np.abs((fits - truth).reshape(-1, 2).mean(axis=0)).max() < 0.01
