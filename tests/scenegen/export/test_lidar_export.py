"""LiDAR point-cloud exports (scenegen.export.lidar): the encoders' bytes read back by hand, and a
dataset without a LiDAR stream refused (the exports of a rendered sweep are read back in
tests/scenegen/pipeline/test_lidar_stream.py)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from scenegen.export.errors import ExportError
from scenegen.export.lidar import POINT_DTYPE, encode_kitti_bin, encode_nuscenes_bin, encode_ply, sweep_points


def points(n=5):
    p = np.zeros(n, POINT_DTYPE)
    p["x"], p["y"], p["z"] = np.arange(n), -np.arange(n), 0.5
    p["intensity"], p["ring"], p["time"], p["range"] = 0.25, np.arange(n) % 3, np.arange(n) * 1e-5, 7.0
    return p


def test_kitti_and_nuscenes_rows_are_float32_without_header():
    p = points()
    k = np.frombuffer(encode_kitti_bin(p), "<f4").reshape(-1, 4)
    assert np.array_equal(k[:, 0], np.arange(5)) and np.all(k[:, 3] == 0.25)
    n = np.frombuffer(encode_nuscenes_bin(p), "<f4").reshape(-1, 5)
    assert np.array_equal(n[:, 4], [0, 1, 2, 0, 1])


def test_ply_header_declares_every_field_and_the_vertex_count():
    data = encode_ply(points(3))
    head, body = data.split(b"end_header\n", 1)
    assert b"element vertex 3" in head and b"property ushort ring" in head and b"property double time" in head
    assert len(body) == 3 * POINT_DTYPE.itemsize


def test_a_dataset_without_a_lidar_stream_is_refused():
    ds = SimpleNamespace(root="out", streams=SimpleNamespace(of_kind=lambda kind: ()))
    with pytest.raises(ExportError, match="out has no LiDAR stream"):
        list(sweep_points(ds))
