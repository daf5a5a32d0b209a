"""Binary PLY meshes (world frame), through trimesh: vertices float32 (the precision Mitsuba
renders with), faces, UVs and vertex colours kept, vertex normals only on request."""
from __future__ import annotations

import io
from pathlib import Path


def encode_ply(mesh, *, vertex_normals: bool = False) -> bytes:
    """Binary PLY bytes of a trimesh.Trimesh."""
    # trimesh on use: it takes ~1 s to import, and only mesh files need it
    from trimesh.exchange.ply import export_ply

    # copy: trimesh's exporter adds UV attributes to the mesh it is given
    return export_ply(mesh.copy(), encoding="binary", vertex_normal=vertex_normals)


def read_ply(path):
    """A PLY file as a trimesh.Trimesh (unprocessed: vertices and faces as stored)."""
    import trimesh  # on use, as above

    return trimesh.load(Path(path), file_type="ply", process=False)


def decode_ply(data: bytes):
    """PLY bytes as a trimesh.Trimesh (unprocessed)."""
    import trimesh  # on use, as above

    return trimesh.load(io.BytesIO(bytes(data)), file_type="ply", process=False)
