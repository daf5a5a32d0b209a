"""Procedural meshes and mesh-file loading, as ``trimesh.Trimesh`` (no Mitsuba).

Every mesh returned here has float64 vertices in metres, int64 faces with counter-clockwise
(outward) winding, so the signed volume of a closed mesh is positive, and per-vertex texture
coordinates in ``mesh.visual.uv`` ((V, 2) float64) in the PROJECT's UV convention
(:mod:`scenegen.geometry.conventions`): u in [0, 1] along texture columns (left to right), v in [0, 1] along
texture rows with v = 0 at the TOP row (image row 0). Seen from outside, every surface shows its
texture upright and unmirrored (the "up" direction of each surface is stated per function).

trimesh itself (and OBJ, glTF as trimesh loads it) uses the OpenGL convention v = 0 at the BOTTOM
row; :func:`uv_to_trimesh` / :func:`uv_from_trimesh` convert (v -> 1 - v). :func:`load_mesh`
returns UVs already converted to ours; convert back before ``mesh.export`` with a texture.

Where UVs need a seam (sphere, cylinder, torus, blob) the seam vertices are duplicated, so these
meshes are watertight geometrically but not by vertex index: merge by position (e.g.
``trimesh.Trimesh(m.vertices, m.faces)``, which merges) before asking ``is_watertight``.

Note for the renderer: spheres and cylinders also exist as analytic Mitsuba primitives
('sphere', 'cylinder'), exact and cheaper; these mesh versions are for export (the dataset's world
meshes), for UV-textured rendering where the primitive's parameterisation differs, and for the
shapes without a primitive (box, torus, blob). Mitsuba's own 'rectangle'/'cube' primitives have
their own UV layout.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from scenegen.assets.checks import check_mesh_arrays, check_mesh_file, count as _count, positive as _positive

#: File extensions :func:`load_mesh` accepts.
MESH_EXTENSIONS = (".ply", ".obj", ".glb", ".gltf", ".stl")


def uv_to_trimesh(uv) -> np.ndarray:
    """Our UVs (v = 0 at the top row) -> trimesh/OpenGL UVs (v = 0 at the bottom row)."""
    uv = np.array(uv, dtype=np.float64)
    uv[:, 1] = 1.0 - uv[:, 1]
    return uv


uv_from_trimesh = uv_to_trimesh  # the flip is its own inverse


def build_mesh(vertices, faces, uv) -> trimesh.Trimesh:
    """A mesh of (V, 3) vertices, (F, 3) faces and (V, 2) UVs in the project's convention, as is
    (no merging or reordering by trimesh)."""
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    uv = np.ascontiguousarray(uv, dtype=np.float64)
    return trimesh.Trimesh(vertices=vertices, faces=faces,
                           visual=trimesh.visual.TextureVisuals(uv=uv), process=False)


def _grid_faces(rows: int, cols: int, flip: bool = False) -> np.ndarray:
    """Two triangles per cell of a (rows + 1) x (cols + 1) vertex grid, index = i * (cols + 1) + j.

    Triangles (a, b, c), (a, c, d) with a = (i, j), b = (i + 1, j), c = (i + 1, j + 1),
    d = (i, j + 1); ``flip`` reverses both.
    """
    i, j = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    a = (i * (cols + 1) + j).ravel()
    b = a + cols + 1
    c = b + 1
    d = a + 1
    f = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return f[:, ::-1] if flip else f


def _quads(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Textured quads from corners (Q, 4, 3) ordered top-left, top-right, bottom-right, bottom-left
    as seen from the front; each quad maps the full texture, UV (0,0) (1,0) (1,1) (0,1)."""
    q = len(corners)
    verts = corners.reshape(-1, 3)
    uv = np.tile([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], (q, 1))
    base = 4 * np.arange(q)[:, None]
    # (TL, BR, TR) and (TL, BL, BR) face the viewer (right x down points away from the viewer).
    faces = np.concatenate([base + [0, 2, 1], base + [0, 3, 2]])
    return verts, faces, uv


def _face_corners(normal, up, half_right: float, half_up: float, offset: float) -> np.ndarray:
    """(4, 3) corners TL, TR, BR, BL of a rectangle with outward ``normal`` at ``offset`` along it,
    seen from outside with ``up`` pointing up; right = (-normal) x up."""
    n, u = np.asarray(normal, float), np.asarray(up, float)
    r = np.cross(-n, u)
    c = n * offset
    return np.stack([c - r * half_right + u * half_up, c + r * half_right + u * half_up,
                     c + r * half_right - u * half_up, c - r * half_right - u * half_up])


# --- procedural shapes ---------------------------------------------------------------------------


def plane(size_xy=(1.0, 1.0)) -> trimesh.Trimesh:
    """Rectangle in z = 0, centred at the origin, normal +z; 4 vertices, 2 triangles.

    The texture is upright seen from +z with +y up: u = x / size_x + 0.5, v = 0.5 - y / size_y.
    """
    sx, sy = (_positive(f"size_xy[{k}]", s) for k, s in enumerate(size_xy))
    v, f, uv = _quads(_face_corners([0, 0, 1], [0, 1, 0], sx / 2, sy / 2, 0.0)[None])
    return build_mesh(v, f, uv)


def box(size_xyz=(1.0, 1.0, 1.0)) -> trimesh.Trimesh:
    """Axis-aligned box centred at the origin; 24 vertices (4 per face), 12 triangles.

    Each face maps the whole texture, upright seen from outside: the four side faces with +z up,
    the top (+z) face with +y up, the bottom (-z) face with +y up seen from below.
    """
    a, b, c = (_positive(f"size_xyz[{k}]", s) / 2 for k, s in enumerate(size_xyz))
    half = {0: a, 1: b, 2: c}
    faces = [  # (normal axis, sign, up vector)
        (0, +1, (0, 0, 1)), (0, -1, (0, 0, 1)), (1, +1, (0, 0, 1)), (1, -1, (0, 0, 1)),
        (2, +1, (0, 1, 0)), (2, -1, (0, 1, 0)),
    ]
    corners = []
    for axis, sign, up in faces:
        n = np.zeros(3)
        n[axis] = sign
        up_axis = int(np.argmax(np.abs(up)))
        right_axis = 3 - axis - up_axis
        corners.append(_face_corners(n, up, half[right_axis], half[up_axis], half[axis]))
    v, f, uv = _quads(np.stack(corners))
    return build_mesh(v, f, uv)


def sphere(radius: float = 1.0, subdivisions: int = 32) -> trimesh.Trimesh:
    """UV sphere centred at the origin: ``subdivisions`` latitude bands, twice as many longitude
    segments.

    Spherical coordinates: theta from +z (north pole), phi = atan2(y, x) in [0, 2 pi);
    u = phi / (2 pi), v = theta / pi (north pole at the top row). The seam (phi = 0, +x side) is
    duplicated; each pole is one vertex per segment, placed at the segment's mid-u.
    Vertices lie exactly on the sphere (an inscribed polyhedron).
    """
    r = _positive("radius", radius)
    n = _count("subdivisions", subdivisions, 2)
    m = 2 * n
    theta = np.pi * np.arange(n + 1) / n
    phi = 2 * np.pi * np.arange(m + 1) / m
    th, ph = np.meshgrid(theta, phi, indexing="ij")  # (n+1, m+1)
    verts = r * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    uv = np.stack([ph / (2 * np.pi), th / np.pi], -1)
    # Pole rows: u at segment centres (one column of each is unused and removed below).
    uv[0, :, 0] = (np.arange(m + 1) + 0.5) / m  # north: cell j uses pole vertex j
    uv[-1, :, 0] = (np.arange(m + 1) - 0.5) / m  # south: cell j uses pole vertex j + 1
    verts[0] = [0, 0, r]
    verts[-1] = [0, 0, -r]
    f = _grid_faces(n, m)  # (a,b,c), (a,c,d): theta x phi -> outward
    cell_row = np.concatenate([np.repeat(np.arange(n), m)] * 2)
    first = np.arange(len(f)) < n * m
    # Drop the degenerate triangle of each polar cell: (a,c,d) at the north row, (a,b,c) at south.
    keep = ~((cell_row == 0) & ~first) & ~((cell_row == n - 1) & first)
    f = f[keep]
    mesh = build_mesh(verts.reshape(-1, 3), f, uv.reshape(-1, 2))
    mesh.remove_unreferenced_vertices()
    return mesh


def cylinder(radius: float = 0.5, height: float = 1.0, sections: int = 64) -> trimesh.Trimesh:
    """Closed cylinder on the z axis, centred at the origin (z in [-height/2, height/2]).

    Side: u = phi / (2 pi) (phi = atan2(y, x), seam at +x duplicated), v = (height/2 - z) / height
    (top edge at the texture's top row). Caps map the texture's inscribed disc: top cap upright seen
    from +z with +y up (u = 0.5 + x/2r, v = 0.5 - y/2r), bottom cap upright seen from -z with +y
    up (u = 0.5 - x/2r, v = 0.5 - y/2r). Rim vertices lie exactly on the circle (an inscribed
    prism: volume pi r^2 h * sin(2 pi/s) / (2 pi/s)).
    """
    r = _positive("radius", radius)
    h = _positive("height", height)
    s = _count("sections", sections, 3)
    phi = 2 * np.pi * np.arange(s + 1) / s
    cx, cy = np.cos(phi), np.sin(phi)
    # Side: a 1 x s grid; row 0 = top.
    side_v = np.concatenate([np.stack([r * cx, r * cy, np.full(s + 1, h / 2)], -1),
                             np.stack([r * cx, r * cy, np.full(s + 1, -h / 2)], -1)])
    side_uv = np.concatenate([np.stack([phi / (2 * np.pi), np.zeros(s + 1)], -1),
                              np.stack([phi / (2 * np.pi), np.ones(s + 1)], -1)])
    side_f = _grid_faces(1, s)  # down x east -> outward (as on the sphere)
    parts = [(side_v, side_f, side_uv)]
    for sign in (+1, -1):
        ring = np.stack([r * cx[:s], r * cy[:s], np.full(s, sign * h / 2)], -1)
        v = np.concatenate([[[0, 0, sign * h / 2]], ring])
        uv = np.stack([0.5 + sign * v[:, 0] / (2 * r), 0.5 - v[:, 1] / (2 * r)], -1)
        j = np.arange(s)
        f = np.stack([np.zeros(s, int), 1 + j, 1 + (j + 1) % s], -1)  # CCW from +z
        parts.append((v, f if sign > 0 else f[:, ::-1], uv))
    return _concat(parts)


def torus(major_radius: float = 1.0, minor_radius: float = 0.25, sections: int = 64,
          minor_sections: int | None = None) -> trimesh.Trimesh:
    """Torus around the z axis, centred at the origin, tube radius ``minor_radius``.

    ``sections`` segments around z, ``minor_sections`` (default sections // 2) around the tube.
    u = phi / (2 pi) around z (seam at +x); v runs around the tube starting at its top
    (z = +minor_radius, v = 0), then the outer equator (v = 0.25), bottom, inner equator, so the
    texture is upright seen from outside the outer equator with +z up. Seams duplicated.
    Vertices lie exactly on the torus; the polyhedron's volume is
    2 pi^2 R r^2 * sinc(2 pi / sections) * sinc(2 pi / minor_sections), sinc(x) = sin(x) / x:
    each of the n = ``sections`` segments is the regular-polygon cross-section P (area
    pi r^2 sinc(2 pi / minor_sections), centroid at distance R) swept between the planes at
    phi_i and phi_i + 2 pi / n, its side quads being planar isosceles trapezoids; in the segment's
    mid-plane frame it is {(x, y, z): (x / c, z) in P, |y| <= x tan(pi / n)} with c = cos(pi / n),
    whose volume is 2 tan(pi / n) c^2 R A(P) = sin(2 pi / n) R A(P).
    """
    R = _positive("major_radius", major_radius)
    r = _positive("minor_radius", minor_radius)
    if r >= R:
        raise ValueError(f"minor_radius ({r}) must be smaller than major_radius ({R})")
    n = _count("sections", sections, 3)
    m = _count("minor_sections", n // 2 if minor_sections is None else minor_sections, 3)
    v_t = np.arange(m + 1) / m
    u_t = np.arange(n + 1) / n
    vv, uu = np.meshgrid(v_t, u_t, indexing="ij")  # rows = around the tube
    theta = np.pi / 2 - 2 * np.pi * vv  # elevation angle on the tube, from the outer equator
    phi = 2 * np.pi * uu
    rho = R + r * np.cos(theta)
    verts = np.stack([rho * np.cos(phi), rho * np.sin(phi), r * np.sin(theta)], -1)
    f = _grid_faces(m, n)  # rows go "down" the tube's outside, columns east -> outward
    return build_mesh(verts.reshape(-1, 3), f, np.stack([uu, vv], -1).reshape(-1, 2))


def _concat(parts) -> trimesh.Trimesh:
    verts, faces, uvs, off = [], [], [], 0
    for v, f, uv in parts:
        verts.append(v)
        faces.append(np.asarray(f) + off)
        uvs.append(uv)
        off += len(v)
    return build_mesh(np.concatenate(verts), np.concatenate(faces), np.concatenate(uvs))


# --- files ---------------------------------------------------------------------------------------


def load_mesh(path) -> trimesh.Trimesh:
    """Load a PLY, OBJ, GLB/GLTF or STL file as one ``trimesh.Trimesh``.

    A file holding a scene (several meshes, node transforms) is flattened: every mesh instance is
    transformed into the file's root frame (faces reversed under a mirroring transform, keeping
    the winding outward) and concatenated, in the scene graph's order. Vertices are kept as stored
    (no merging or reordering), as float64. UVs are kept when every instance has them, converted
    to the project's convention (v = 0 at the top row); the file's material is kept on
    ``mesh.visual.material`` only for a single-instance file. The flattening is done here, not by
    trimesh's ``Scene.to_mesh``, which copies materials and needs Pillow for that.

    Raises ValueError naming the file when it is missing, of an unsupported type, unreadable, or
    has no triangles.
    """
    p = Path(path)
    ext = p.suffix.lower()
    if ext not in MESH_EXTENSIONS:
        raise ValueError(f"mesh file {str(p)!r}: unsupported extension {ext!r}; "
                         f"supported: {', '.join(MESH_EXTENSIONS)}")
    check_mesh_file(p)  # a directory, missing, empty or too large: ValueError naming it
    try:
        scene = trimesh.load_scene(str(p), process=False)
        parts = []  # (vertices, faces, uv or None, material or None)
        for node in scene.graph.nodes_geometry:
            transform, name = scene.graph[node]
            g = scene.geometry[name]
            if not isinstance(g, trimesh.Trimesh) or len(g.faces) == 0:
                continue
            T = np.asarray(transform, dtype=np.float64)
            v = np.asarray(g.vertices, dtype=np.float64) @ T[:3, :3].T + T[:3, 3]
            f = np.asarray(g.faces, dtype=np.int64)
            if np.linalg.det(T[:3, :3]) < 0:
                f = f[:, ::-1]
            vis = g.visual
            uv = None
            if isinstance(vis, trimesh.visual.TextureVisuals) and vis.uv is not None \
                    and len(vis.uv) == len(v):
                uv = uv_from_trimesh(vis.uv)
            parts.append((v, f, uv, getattr(vis, "material", None)))
    except Exception as e:  # trimesh raises many types on corrupt files
        raise ValueError(f"mesh file {str(p)!r}: could not be read ({type(e).__name__}: {e})") \
            from None
    if not parts:
        raise ValueError(f"mesh file {str(p)!r}: it contains no triangles")
    offsets = np.cumsum([0] + [len(v) for v, *_ in parts])[:-1]
    verts = np.concatenate([v for v, *_ in parts])
    faces = np.concatenate([f + o for (_, f, *_), o in zip(parts, offsets)])
    check_mesh_arrays(str(p), verts, faces)
    visual = None
    if all(uv is not None for _, _, uv, _ in parts):
        material = parts[0][3] if len(parts) == 1 else None
        visual = trimesh.visual.TextureVisuals(
            uv=np.concatenate([uv for _, _, uv, _ in parts]), material=material)
    return trimesh.Trimesh(vertices=verts, faces=faces, visual=visual, process=False)

