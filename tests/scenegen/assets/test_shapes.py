"""Tests for scenegen.assets.shapes: closedness, winding, analytic size, UVs, determinism, file loading."""
from __future__ import annotations

import numpy as np
import pytest
import trimesh

from scenegen.assets import blob, shapes

# Exact-arithmetic checks (closed-form polyhedron volumes) are floored by float64 summation over a
# few thousand triangles: ~1e-15 relative per term.
EXACT_REL_TOL = 1e-10


def _sinc(x: float) -> float:
    return np.sin(x) / x


def _merged(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """The same surface with UV-seam duplicates merged by position (trimesh merges on process)."""
    return trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)


def _inscribed_cos_alpha(mesh: trimesh.Trimesh, radius: float) -> float:
    """cos of the largest angular radius of the sphere cap cut off by any face's plane.

    Every vertex lies on the sphere, so each face's plane cuts the sphere in a circle through its
    three corners at distance d = r cos(alpha) from the centre, and every point of the face is at
    distance >= d from the centre.
    """
    d = np.abs(np.einsum("ij,ij->i", mesh.face_normals, mesh.vertices[mesh.faces[:, 0]]))
    return float(d.min() / radius)


ALL_SHAPES = {
    "plane": lambda: shapes.plane((2.0, 1.0)),
    "box": lambda: shapes.box((1.0, 2.0, 3.0)),
    "sphere": lambda: shapes.sphere(0.7, 24),
    "cylinder": lambda: shapes.cylinder(0.5, 2.0, 48),
    "torus": lambda: shapes.torus(1.0, 0.3, 48, 20),
    "blob": lambda: blob.blob(1.0, 0.3, 1.5, 7, 3),
}
CLOSED = [k for k in ALL_SHAPES if k != "plane"]


@pytest.mark.parametrize("name", ["sphere", "cylinder", "torus", "blob"])
def test_no_triangle_spans_the_uv_seam(name):
    m = ALL_SHAPES[name]()
    u_span = np.ptp(m.visual.uv[m.faces][:, :, 0], axis=1)  # (F,)
    # Largest legitimate u span: a cylinder cap triangle (centre to rim, half the texture); a
    # triangle wrapping around the seam would span ~1.
    assert u_span.max() <= 0.5 + 1e-12


@pytest.mark.parametrize("name", list(ALL_SHAPES))
class TestCommon:
    def test_types_and_uv_range(self, name):
        m = ALL_SHAPES[name]()
        assert m.vertices.dtype == np.float64 and m.faces.dtype == np.int64
        uv = m.visual.uv
        assert uv.shape == (len(m.vertices), 2)
        assert uv.min() >= 0.0 and uv.max() <= 1.0
        assert not np.any(m.area_faces <= 0), "degenerate triangle"



@pytest.mark.parametrize("name", CLOSED)
def test_closed_and_outward(name):
    g = _merged(ALL_SHAPES[name]())
    assert g.is_watertight and g.is_winding_consistent
    assert g.volume > 0  # signed volume > 0 <=> normals point outward


class TestPlane:
    def test_geometry_and_uv(self):
        m = shapes.plane((2.0, 1.0))
        assert np.allclose(m.face_normals, [0, 0, 1])
        assert m.area == pytest.approx(2.0)
        assert np.allclose(m.vertices[:, 2], 0) and np.allclose(m.vertices.mean(0), 0)
        # u = x / sx + 0.5, v = 0.5 - y / sy (texture upright seen from +z, +y up).
        x, y = m.vertices[:, 0], m.vertices[:, 1]
        assert np.allclose(m.visual.uv, np.stack([x / 2 + 0.5, 0.5 - y / 1.0], 1))

    def test_rejects_bad_size(self):
        with pytest.raises(ValueError, match="size_xy"):
            shapes.plane((0.0, 1.0))


class TestBox:
    def test_volume_area_and_normals(self):
        m = shapes.box((1.0, 2.0, 3.0))
        assert m.volume == pytest.approx(6.0, rel=EXACT_REL_TOL)
        assert m.area == pytest.approx(2 * (2 + 3 + 6), rel=EXACT_REL_TOL)
        assert len(m.vertices) == 24
        # Every face normal is the axis direction of its face, pointing away from the centre.
        centroids = m.triangles_center
        dots = np.einsum("ij,ij->i", m.face_normals, centroids)
        assert np.all(dots > 0)

    def test_side_faces_upright(self):
        """On the side faces v grows downward (-z); on the +z face v grows towards -y."""
        m = shapes.box((1.0, 1.0, 1.0))
        for f in range(12):
            n = m.face_normals[f]
            vid = m.faces[f]
            p, uv = m.vertices[vid], m.visual.uv[vid]
            # Solve uv = A p_tangent + c for the face; check dv/dz (sides) or dv/dy (top).
            A = np.c_[p, np.ones(3)]
            coef, *_ = np.linalg.lstsq(A, uv, rcond=None)
            if abs(n[2]) < 0.5:
                assert coef[2, 1] == pytest.approx(-1.0)  # dv/dz
            elif n[2] > 0:
                assert coef[1, 1] == pytest.approx(-1.0)  # dv/dy, +y is up on the top face
                assert coef[0, 0] == pytest.approx(1.0)  # du/dx


class TestSphere:
    @pytest.mark.parametrize("subdiv", [8, 32])
    def test_volume_and_area_within_inscribed_bound(self, subdiv):
        r = 0.7
        m = shapes.sphere(r, subdiv)
        assert np.allclose(np.linalg.norm(m.vertices, axis=1), r)
        # The polyhedron lies between the spheres of radius r cos(alpha) and r, and each face is the
        # radial projection of its cap scaled by (d/r)^2 cos(gamma) >= cos(alpha)^3; so both the
        # volume and the area deficits are in [0, 1 - cos(alpha)^3].
        tol = 1 - _inscribed_cos_alpha(m, r) ** 3
        assert 0 < tol < 0.2  # sanity: the bound is informative
        for got, exact in ((m.volume, 4 / 3 * np.pi * r**3), (m.area, 4 * np.pi * r**2)):
            deficit = 1 - got / exact
            assert 0 <= deficit <= tol

    def test_uv_is_spherical(self):
        m = shapes.sphere(1.0, 16)
        x, y, z = m.vertices.T
        away = np.hypot(x, y) > 1e-9
        phi = np.mod(np.arctan2(y, x), 2 * np.pi)
        u, v = m.visual.uv.T
        assert np.allclose(v, np.arccos(np.clip(z, -1, 1)) / np.pi)
        seam = away & (np.abs(y) < 1e-12) & (x > 0)
        assert np.allclose(u[away & ~seam], phi[away & ~seam] / (2 * np.pi))
        assert set(np.round(u[seam], 12)) == {0.0, 1.0}


class TestCylinder:
    def test_exact_prism_and_analytic_bound(self):
        r, h, s = 0.5, 2.0, 48
        m = shapes.cylinder(r, h, s)
        # Inscribed regular s-gon: area (s/2) r^2 sin(2 pi / s) = pi r^2 sinc(2 pi / s); perimeter
        # 2 s r sin(pi / s).
        poly_area = np.pi * r**2 * _sinc(2 * np.pi / s)
        perimeter = 2 * s * r * np.sin(np.pi / s)
        assert m.volume == pytest.approx(poly_area * h, rel=EXACT_REL_TOL)
        assert m.area == pytest.approx(2 * poly_area + perimeter * h, rel=EXACT_REL_TOL)
        tol = 1 - _sinc(2 * np.pi / s)  # the volume deficit, derived from the tessellation
        assert 1 - m.volume / (np.pi * r**2 * h) == pytest.approx(tol, rel=1e-9)
        assert np.isclose(m.bounds[:, 2], [-h / 2, h / 2]).all()

    def test_side_uv(self):
        m = shapes.cylinder(0.5, 2.0, 16)
        side = np.abs(np.hypot(m.vertices[:, 0], m.vertices[:, 1]) - 0.5) < 1e-12
        side &= np.isin(np.arange(len(m.vertices)), m.faces[:16 * 2])
        v = m.visual.uv[side, 1]
        assert np.allclose(v, (1.0 - m.vertices[side, 2]) / 2.0)


class TestTorus:
    def test_exact_polyhedron_and_analytic_bound(self):
        R, r, n, k = 1.0, 0.3, 48, 20
        m = shapes.torus(R, r, n, k)
        # Each of the n segments is the k-gon cross-section swept between two planes; its volume is
        # sin(2 pi / n) R A(k-gon) (derived in the docstring of shapes.torus), so the polyhedron's
        # volume is 2 pi^2 R r^2 sinc(2 pi / n) sinc(2 pi / k).
        factor = _sinc(2 * np.pi / n) * _sinc(2 * np.pi / k)
        exact = 2 * np.pi**2 * R * r**2
        # So the deficit against the analytic torus is exactly 1 - factor (~1.9% here).
        assert m.volume == pytest.approx(exact * factor, rel=EXACT_REL_TOL)
        # Area: same order of deficit; bounded by twice the volume's (measured ~1x).
        assert 0 < 1 - m.area / (4 * np.pi**2 * R * r) <= 2 * (1 - factor)

    def test_rejects_self_intersecting(self):
        with pytest.raises(ValueError, match="minor_radius"):
            shapes.torus(1.0, 1.0)


class TestBlob:
    def test_seed_determinism(self):
        a = blob.blob(1.0, 0.3, 2.0, seed=5, subdivisions=3)
        b = blob.blob(1.0, 0.3, 2.0, seed=5, subdivisions=3)
        c = blob.blob(1.0, 0.3, 2.0, seed=6, subdivisions=3)
        assert a.vertices.tobytes() == b.vertices.tobytes()
        assert a.faces.tobytes() == b.faces.tobytes()
        assert a.visual.uv.tobytes() == b.visual.uv.tobytes()
        assert not np.allclose(a.vertices, c.vertices)

    def test_radius_bounds_and_zero_amplitude(self):
        m = blob.blob(2.0, 0.25, 1.0, seed=1, subdivisions=3)
        d = np.linalg.norm(m.vertices, axis=1)
        assert d.min() >= 2.0 * 0.75 - 1e-12 and d.max() <= 2.0 * 1.25 + 1e-12
        assert d.max() - d.min() > 0.2  # it is displaced
        flat = blob.blob(2.0, 0.0, 1.0, seed=1, subdivisions=3)
        assert np.allclose(np.linalg.norm(flat.vertices, axis=1), 2.0)

    def test_uv_from_spherical_coords(self):
        m = blob.blob(1.0, 0.3, 1.0, seed=2, subdivisions=3)
        p = m.vertices / np.linalg.norm(m.vertices, axis=1, keepdims=True)
        assert np.allclose(m.visual.uv[:, 1], np.arccos(np.clip(p[:, 2], -1, 1)) / np.pi)
        ok = (np.hypot(p[:, 0], p[:, 1]) > 1e-9) & ~((np.abs(p[:, 1]) < 1e-12) & (p[:, 0] > 0))
        phi = np.mod(np.arctan2(p[ok, 1], p[ok, 0]), 2 * np.pi)
        assert np.allclose(m.visual.uv[ok, 0], phi / (2 * np.pi))

    def test_zero_amplitude_volume_within_inscribed_bound(self):
        m = blob.blob(1.0, 0.0, 1.0, seed=0, subdivisions=4)
        tol = 1 - _inscribed_cos_alpha(m, 1.0) ** 3
        assert 0 <= 1 - m.volume / (4 / 3 * np.pi) <= tol

    def test_rejects_amplitude_one(self):
        with pytest.raises(ValueError, match="amplitude"):
            blob.blob(amplitude=1.0)


# --- loading files ---------------------------------------------------------------------------


def _write_obj(path, mesh: trimesh.Trimesh) -> None:
    """Hand-written OBJ with per-vertex vt; OBJ's v = 0 is the image's BOTTOM row."""
    uv_obj = shapes.uv_to_trimesh(mesh.visual.uv)
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in mesh.vertices]
    lines += [f"vt {u:.17g} {v:.17g}" for u, v in uv_obj]
    lines += ["f " + " ".join(f"{i + 1}/{i + 1}" for i in face) for face in mesh.faces]
    path.write_text("\n".join(lines) + "\n")


def _write_gltf(path, mesh: trimesh.Trimesh) -> None:
    """Hand-written glTF 2.0 (embedded buffer) with TEXCOORD_0.

    glTF's UV origin is the image's top-left corner, v down: the same as ours, so TEXCOORD_0 holds
    our UVs verbatim (trimesh flips them to OpenGL's on load; load_mesh flips them back).
    """
    import base64
    import json

    pos = mesh.vertices.astype(np.float32)
    uv = mesh.visual.uv.astype(np.float32)
    idx = mesh.faces.astype(np.uint32).ravel()
    blob = pos.tobytes() + uv.tobytes() + idx.tobytes()
    views, accessors, offset = [], [], 0
    for arr, typ, comp, count in ((pos, "VEC3", 5126, len(pos)), (uv, "VEC2", 5126, len(uv)),
                                  (idx, "SCALAR", 5125, len(idx))):
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": arr.nbytes})
        acc = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": typ}
        if typ == "VEC3":
            acc["min"], acc["max"] = pos.min(0).tolist(), pos.max(0).tolist()
        accessors.append(acc)
        offset += arr.nbytes
    gltf = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                    "indices": 2, "material": 0}]}],
        # trimesh keeps TEXCOORD_0 only on a primitive with a material.
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0]}}],
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(blob).decode()}],
        "bufferViews": views, "accessors": accessors,
    }
    path.write_text(json.dumps(gltf))


@pytest.mark.parametrize("ext", [".ply", ".obj", ".glb", ".gltf", ".stl"])
def test_load_mesh_roundtrip(tmp_path, ext):
    src = shapes.box((1.0, 2.0, 3.0))
    path = tmp_path / f"box{ext}"
    if ext == ".obj":
        _write_obj(path, src)
    elif ext == ".gltf":
        _write_gltf(path, src)
    else:  # trimesh's own writers (geometry only: its textured writers need Pillow)
        trimesh.Trimesh(src.vertices, src.faces, process=False).export(path)
    m = shapes.load_mesh(path)
    assert m.vertices.dtype == np.float64 and m.faces.dtype == np.int64
    assert m.volume == pytest.approx(6.0, rel=1e-6)  # float32 in GLB/glTF/STL
    assert _merged(m).is_watertight
    if ext in (".obj", ".gltf"):
        # Every corner position carries the same (our-convention) UV as in the source mesh.
        def keys(mesh):
            return sorted(tuple(np.round(np.r_[p, t], 5)) for p, t in zip(mesh.vertices,
                                                                        mesh.visual.uv))
        assert keys(m) == keys(src)


def test_load_mesh_scene_applies_transforms(tmp_path):
    scene = trimesh.Scene()
    a = shapes.box((1.0, 1.0, 1.0))
    scene.add_geometry(trimesh.Trimesh(a.vertices, a.faces), node_name="a",
                       transform=trimesh.transformations.translation_matrix([10.0, 0, 0]))
    scene.add_geometry(trimesh.Trimesh(a.vertices, a.faces), node_name="b",
                       transform=trimesh.transformations.translation_matrix([0, -5.0, 0]))
    path = tmp_path / "two.glb"
    scene.export(path)
    m = shapes.load_mesh(path)
    assert len(m.faces) == 24
    assert m.volume == pytest.approx(2.0, rel=1e-6)
    assert np.allclose(m.bounds, [[-0.5, -5.5, -0.5], [10.5, 0.5, 0.5]])


def test_load_mesh_errors_name_the_file(tmp_path):
    with pytest.raises(ValueError, match="nope.ply.*not found"):
        shapes.load_mesh(tmp_path / "nope.ply")
    bad = tmp_path / "bad.xyz"
    bad.write_text("1 2 3")
    with pytest.raises(ValueError, match="bad.xyz.*unsupported"):
        shapes.load_mesh(bad)
    garbage = tmp_path / "garbage.glb"
    garbage.write_bytes(b"\x00not a glb at all")
    with pytest.raises(ValueError, match="garbage.glb"):
        shapes.load_mesh(garbage)
    empty = tmp_path / "empty.obj"
    empty.write_text("# nothing\n")
    with pytest.raises(ValueError, match="empty.obj"):
        shapes.load_mesh(empty)
