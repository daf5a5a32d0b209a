"""Argument checks shared by the asset builders (ValueError naming the argument)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

#: Most triangles of one loaded mesh file (and most bytes of the file). Why: the renderer uploads
#: the mesh and the dataset keeps a float64 copy for truth and export (~100 bytes per triangle):
#: 50 million triangles are ~5 GB; a larger scan belongs decimated in the spec.
MAX_MESH_FACES = 50_000_000
MAX_MESH_FILE_BYTES = 4 << 30
#: Most pixels of a procedural texture: 2^26 (as an image, scenegen.spec.model.limits). Why: it is
#: made as float64 RGB (24 bytes per texel, 1.6 GB at this size) before the renderer gets it.
MAX_TEXTURE_PIXELS = 1 << 26
#: Environment map files: what the renderer's image reader (Mitsuba's Bitmap) reads among the
#: spec's image suffixes: no TIFF.
ENVMAP_SUFFIXES = (".exr", ".hdr", ".png", ".jpg", ".jpeg", ".bmp")


def positive(name: str, value) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be a positive number, got {value!r}")
    return v


def count(name: str, value, minimum: int) -> int:
    if int(value) != value or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def check_mesh_file(p: Path) -> None:
    """ValueError naming the mesh file ``p`` when it is a directory, missing, empty or too large."""
    if p.is_dir():
        raise ValueError(f"mesh file {str(p)!r}: is a directory, expected a mesh file")
    if not p.is_file():
        raise ValueError(f"mesh file {str(p)!r}: file not found")
    size = p.stat().st_size
    if size == 0:
        raise ValueError(f"mesh file {str(p)!r}: the file is empty")
    if size > MAX_MESH_FILE_BYTES:
        raise ValueError(f"mesh file {str(p)!r}: {size / 2**30:.1f} GiB; at most {MAX_MESH_FILE_BYTES / 2**30:.0f}"
                         " GiB are read (MAX_MESH_FILE_BYTES, docs/scene_spec.md 'Limits'): decimate it")


def check_mesh_arrays(what: str, vertices: np.ndarray, faces: np.ndarray) -> None:
    """ValueError naming ``what`` for a mesh the renderer and the truth cannot use: more than
    MAX_MESH_FACES triangles, a NaN or infinite vertex, a face index outside the vertex list."""
    if len(faces) > MAX_MESH_FACES:
        raise ValueError(f"mesh file {what!r}: {len(faces):,} triangles; at most {MAX_MESH_FACES:,} "
                         "(MAX_MESH_FACES, docs/scene_spec.md 'Limits'): decimate it")
    bad = ~np.isfinite(vertices).all(axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(f"mesh file {what!r}: vertex {k} is not finite ({vertices[k].tolist()}); "
                         f"{int(bad.sum())} such vertices")
    if len(faces) and (faces.min() < 0 or faces.max() >= len(vertices)):
        raise ValueError(f"mesh file {what!r}: a face refers to vertex {int(faces.max())} (or "
                         f"{int(faces.min())}) of {len(vertices)}")
