"""Point clouds and triangle meshes (PLY; also OBJ/STL, by extension) through trimesh."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from recon_eval.errors import InputError


@dataclass(frozen=True)
class Geometry:
    """vertices (N, 3) float64 metres; faces (F, 3) int64 or None for a point cloud."""

    vertices: np.ndarray
    faces: np.ndarray | None
    path: str


def read_geometry(path) -> Geometry:
    """Read a point cloud or mesh. A file with faces is a mesh; a cloud has faces None. An empty
    file (no vertices) is allowed (metrics define empty-cloud scores)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a point cloud or mesh: .ply, .obj, .stl)")
    try:
        obj = trimesh.load(str(p), process=False)
    except Exception as exc:  # trimesh raises many types on malformed files
        raise InputError(f"{p}: cannot read as a point cloud or mesh ({type(exc).__name__}: {exc})") from None
    if isinstance(obj, trimesh.Scene):
        geoms = list(obj.geometry.values())
        if len(geoms) == 0:
            return Geometry(np.zeros((0, 3)), None, str(p))
        if len(geoms) != 1:
            raise InputError(f"{p}: expected one point cloud or mesh, found a scene of {len(geoms)}")
        obj = geoms[0]
    V = np.asarray(getattr(obj, "vertices", np.zeros((0, 3))), dtype=np.float64).reshape(-1, 3)
    F = getattr(obj, "faces", None)
    F = None if F is None or len(F) == 0 else np.asarray(F, dtype=np.int64)
    if not np.all(np.isfinite(V)):
        raise InputError(f"{p}: {int(np.sum(~np.all(np.isfinite(V), axis=1)))} vertices are not finite")
    return Geometry(V, F, str(p))


def write_point_cloud_ply(path, points) -> None:
    """Write (N, 3) points as a binary little-endian PLY (float64 x, y, z)."""
    pts = np.ascontiguousarray(np.asarray(points, dtype="<f8").reshape(-1, 3))
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(pts)}\nproperty double x\nproperty double y\nproperty double z\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(pts.tobytes())
