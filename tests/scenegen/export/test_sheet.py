"""The contact sheet's pictures: depth colours over the view's range (a frontal plane one colour),
normals as (n + 1) / 2, one fixed colour per instance id, rows laid out as documented."""
import cv2
import numpy as np

import pytest

from scenegen.export.sheet import (
    GAP_PX, KINDS, LABEL_PX, MAX_SHEET_PIXELS, MAX_TILE_WIDTH_PX, check_sheet_size, check_tile_width, compose,
    depth_tile, id_colours, normals_tile, resized, view_tiles,
)
from scenegen.spec.model.limits import MAX_IMAGE_SIDE_PX


def test_depth_colours_span_the_views_range():
    d = np.linspace(1.0, 3.0, 12).reshape(3, 4)
    valid = np.ones_like(d, bool)
    valid[0, 0] = False
    rgb, rng = depth_tile(d, valid)
    assert rng == (d[valid].min(), 3.0) and (rgb[0, 0] == 0).all()
    turbo = cv2.applyColorMap(np.arange(256, dtype=np.uint8)[:, None], cv2.COLORMAP_TURBO)[:, 0, ::-1]
    assert (rgb[2, 3] == turbo[0]).all() and (rgb[0, 1] == turbo[255]).all()  # far = turbo(0), near = turbo(255)
    flat, _ = depth_tile(np.full((4, 4), 0.24) + np.random.default_rng(0).normal(0, 1e-7, (4, 4)), np.ones((4, 4), bool))
    assert len(np.unique(flat.reshape(-1, 3), axis=0)) <= 2  # float noise on a frontal plane is not amplified


def test_normals_and_ids():
    n = np.array([[[1.0, 0, 0], [0, -1.0, 0], [np.nan] * 3]])
    rgb = normals_tile(n, np.array([[True, True, False]]))
    assert rgb.tolist() == [[[255, 128, 128], [128, 0, 128], [0, 0, 0]]]
    ids = np.array([0, 1, 2, 1, 300000])
    c = id_colours(ids)
    assert (c[0] == 0).all() and (c[1] == c[3]).all() and not (c[1] == c[2]).all() and (c[1:] >= 64).all()


def test_rows_are_laid_out_as_documented():
    tiles = [np.zeros((10, 16, 3), np.uint8)] * 4
    sheet = compose([("a", tiles), ("b", tiles)])
    assert sheet.shape == (2 * (LABEL_PX + 10 + GAP_PX), 4 * 16 + 3 * GAP_PX, 3)


def test_the_sheet_size_is_known_before_any_tile_is_made():
    """check_sheet_size computes what compose makes (so the limit is checked before rendering or
    reading anything), and the limits hold: the widest sheet is about the spec's image side."""
    sizes = [(64, 48), (33, 77), (640, 10)]
    truth = lambda w, h: {"valid": np.ones((h, w), bool), "depth_z": np.ones((h, w)),  # noqa: E731
                          "normals_cam": np.zeros((h, w, 3)), "instance_id": np.zeros((h, w), np.uint32)}
    rows = [(f"v{i}", view_tiles(np.zeros((h, w, 3), np.uint8), truth(w, h), 50)[0]) for i, (w, h) in enumerate(sizes)]
    assert check_sheet_size(50, sizes) == compose(rows).shape[1::-1]
    assert len(KINDS) * MAX_TILE_WIDTH_PX + 3 * GAP_PX - MAX_IMAGE_SIDE_PX < 16
    assert check_tile_width(16) == 16 and check_tile_width(MAX_TILE_WIDTH_PX) == MAX_TILE_WIDTH_PX
    for bad in (15, MAX_TILE_WIDTH_PX + 1, 10**8):
        with pytest.raises(ValueError, match="--tile-width: expected 16 to 4,096 pixels"):
            check_tile_width(bad)
    views = MAX_SHEET_PIXELS // ((len(KINDS) * 160 + 3 * GAP_PX) * (LABEL_PX + 120 + GAP_PX)) + 1
    with pytest.raises(ValueError, match=f"the contact sheet of {views:,} views would be"):
        check_sheet_size(160, [(640, 480)] * views)
    assert resized(np.zeros((48, 64, 3), np.uint8), 160).shape[:2] == (120, 160)
