"""A spec object's geometry as triangles: in its object frame, and placed in the world (float64).

The world meshes are what the dataset stores (``scene/meshes/<object>.ply``) and what the
renderer uploads (float32), so both are the same triangles. Read by attribute from the spec's
geometry records (their ``kind``), so this module does not import the spec layer.
"""
from __future__ import annotations

import numpy as np
import trimesh

from scenegen.assets import blob, cache, shapes, targets, textures
from scenegen.geometry.conventions import zup_from_mesh_file

#: Spec geometry kind -> its object-frame mesh (all centred on the object origin).
OBJECT_MESHES = {
    "plane": lambda g: shapes.plane(g.size),
    "box": lambda g: shapes.box(g.size),
    "sphere": lambda g: shapes.sphere(g.radius),
    "cylinder": lambda g: shapes.cylinder(g.radius, g.height),
    "torus": lambda g: shapes.torus(g.major_radius, g.minor_radius),
    "blob": lambda g: cached_blob(g.radius, g.amplitude, g.frequency, g.seed, g.subdivisions),
    "mesh": lambda g: file_mesh(g.path, g.up_axis, getattr(g, "scale", 1.0)),
}
TARGET_KINDS = ("checkerboard", "charuco", "aruco_grid")
#: Kinds whose shading normals are interpolated (curved surfaces approximated by triangles).
SMOOTH_KINDS = ("cylinder", "torus", "blob", "sphere")


def file_mesh(path, up_axis: str, scale: float = 1.0) -> trimesh.Trimesh:
    """A mesh file in our Z-up object frame: a Y-up file (glTF) turned by the one conversion of
    :func:`scenegen.geometry.conventions.zup_from_mesh_file`, then times ``scale`` (metres per
    file unit; UVs kept)."""
    mesh = shapes.load_mesh(path)
    if up_axis == "z" and scale == 1.0:
        return mesh
    return trimesh.Trimesh(vertices=zup_from_mesh_file(mesh.vertices, up_axis) * float(scale), faces=mesh.faces,
                           visual=mesh.visual, process=False)


def object_mesh(geometry) -> tuple[trimesh.Trimesh, "targets.Board | None"]:
    """(trimesh in the object frame, the Board for a calibration target else None)."""
    if geometry.kind in TARGET_KINDS:
        board = targets.board_from_spec(geometry)
        # the spec's target object is the board centred on its origin, print facing +z
        mesh = board.mesh()
        mesh.vertices = board.object_from_board().apply(mesh.vertices)
        return mesh, board
    return OBJECT_MESHES[geometry.kind](geometry), None


def place(mesh: trimesh.Trimesh, transform) -> trimesh.Trimesh:
    """Object -> world in float64: scale, then rotate and translate (UVs kept). ``transform`` has
    ``scale`` (3,) and ``world_from_object`` (Rigid3)."""
    v = np.asarray(mesh.vertices, dtype=np.float64) * np.asarray(transform.scale, dtype=np.float64)
    v = transform.world_from_object.apply(v)
    faces = np.asarray(mesh.faces)
    if np.prod(transform.scale) < 0:  # a mirroring scale flips the winding
        faces = faces[:, ::-1]
    out = trimesh.Trimesh(vertices=v, faces=faces, process=False)
    uv = getattr(mesh.visual, "uv", None)
    if uv is not None:
        out.visual = trimesh.visual.TextureVisuals(uv=np.asarray(uv, dtype=np.float64))
    return out


def is_faceted(mesh: trimesh.Trimesh) -> bool:
    """A loaded mesh with per-face vertices (no shared vertices) is flat-shaded."""
    return len(mesh.vertices) >= 3 * len(mesh.faces)


def is_smooth(geometry, object_mesh_: trimesh.Trimesh, world: trimesh.Trimesh) -> bool:
    """Whether the object's shading normals are interpolated: curved shapes, and loaded meshes
    that share vertices between faces."""
    return geometry.kind in SMOOTH_KINDS or (geometry.kind == "mesh" and len(world.faces) > 0
                                             and not is_faceted(object_mesh_))


def texture_image(texture) -> np.ndarray:
    """Linear float32 (H, W, 3) reflectance of a spec texture (image file or procedural); a
    procedural one is made once per content hash (:mod:`scenegen.assets.cache`), read-only."""
    if texture.kind == "image":
        return textures.load_image(texture.path)
    params = dict(texture.params)
    key = {"kind": texture.kind, "params": params, "seed": texture.seed}
    make = lambda: {"image": textures.make_texture(texture.kind, params, texture.seed)}
    return cache.cached_arrays("texture", key, make)["image"]


def cached_blob(radius, amplitude, frequency, seed, subdivisions) -> trimesh.Trimesh:
    """:func:`scenegen.assets.blob.blob`, made once per content hash (:mod:`scenegen.assets.cache`)."""
    def make():
        m = blob.blob(radius, amplitude, frequency, seed, subdivisions)
        return {"vertices": m.vertices, "faces": m.faces, "uv": m.visual.uv}

    key = {"radius": radius, "amplitude": amplitude, "frequency": frequency, "seed": seed,
           "subdivisions": subdivisions}
    a = cache.cached_arrays("blob", key, make)
    return trimesh.Trimesh(vertices=a["vertices"].copy(), faces=a["faces"].copy(),
                           visual=trimesh.visual.TextureVisuals(uv=a["uv"].copy()), process=False)
