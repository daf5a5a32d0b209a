"""A mesh file's up axis: glTF 2.0 is Y-up by its specification and enters our Z-up world turned
+90 degrees about x (one conversion, scenegen.geometry.conventions); other formats are read Z-up;
`mesh: {path, up_axis}` overrides either (docs/conventions.md, "Mesh files")."""
import numpy as np
import pytest
import trimesh

from scenegen.assets.meshes import file_mesh, object_mesh
from scenegen.errors import SpecError
from scenegen.geometry.conventions import Z_UP_FROM_Y_UP, mesh_up_axis, zup_from_mesh_file
from scenegen.spec import load_spec, to_yaml
from scenegen.spec.load import parse_spec

# glTF: +Y up, +Z the asset's front; a Blender (Z-up) export writes (x, y, z) as (x, z, -y)
FILE_POINTS = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.3, -0.2, 0.7]])


def test_the_y_up_rotation_is_blenders_gltf_axes_and_a_rotation():
    blender = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])  # (x, y, z) -> (x, -z, y): io_import_scene_gltf2
    ref = trimesh.transformations.rotation_matrix(np.pi / 2, [1, 0, 0])[:3, :3]  # +90 deg about x
    np.testing.assert_allclose(Z_UP_FROM_Y_UP, ref, atol=1e-15)
    np.testing.assert_allclose(zup_from_mesh_file(FILE_POINTS, "y"), FILE_POINTS @ blender.T, atol=1e-15)
    np.testing.assert_array_equal(zup_from_mesh_file(FILE_POINTS, "z"), FILE_POINTS)
    up, front = zup_from_mesh_file(FILE_POINTS[:2], "y")
    np.testing.assert_allclose(up, [0, 0, 1])  # the file's up is our up
    np.testing.assert_allclose(front, [0, -1, 0], atol=1e-16)  # its front faces -y
    assert [mesh_up_axis(s) for s in (".glb", ".GLTF", ".obj", ".ply", ".stl")] == ["y", "y", "z", "z", "z"]


def _tri(path):
    m = trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 2, 0]], faces=[[0, 1, 2]], process=False)
    m.export(path)


@pytest.mark.parametrize("ext,written,expect_axis", [
    (".glb", "{mesh}", "y"), (".glb", "{{path: {mesh}, up_axis: z}}", "z"),
    (".obj", "{mesh}", "z"), (".obj", "{{path: {mesh}, up_axis: y}}", "y")])
def test_the_spec_reads_the_default_and_the_override(tmp_path, ext, written, expect_axis):
    _tri(tmp_path / f"t{ext}")
    text = f"name: u\nobjects:\n  - name: t\n    mesh: {written.format(mesh='t' + ext)}\n"
    (tmp_path / "u.yaml").write_text(text)
    spec = load_spec(tmp_path / "u.yaml")
    g = spec.objects[0].geometry
    assert g.up_axis == expect_axis
    mesh, _ = object_mesh(g)
    raw = np.array([[0, 0, 0], [1, 0, 0], [0, 2, 0.0]])
    want = raw @ Z_UP_FROM_Y_UP.T if expect_axis == "y" else raw
    np.testing.assert_allclose(np.asarray(mesh.vertices), want, atol=1e-7)  # (0, 2, 0) up: (0, 0, 2)
    back = parse_spec(to_yaml(spec), file="<rt>", base_dir=spec.base_dir)
    assert back.objects[0].geometry.up_axis == expect_axis


def test_a_bad_up_axis_names_the_field(tmp_path):
    _tri(tmp_path / "t.glb")
    (tmp_path / "u.yaml").write_text("name: u\nobjects:\n  - name: t\n    mesh: {path: t.glb, up_axis: x}\n")
    with pytest.raises(SpecError, match=r"u.yaml:4: objects\[0\]\.mesh\.up_axis: .*'x'"):
        load_spec(tmp_path / "u.yaml")


def test_the_resolved_spec_of_a_non_gltf_mesh_keeps_its_form(tmp_path):
    """up_axis 'z' is omitted from the resolved spec, so existing specs with OBJ/PLY/STL meshes keep
    their hash; a glTF records its 'y'."""
    from scenegen.spec.serialize import spec_to_dict
    _tri(tmp_path / "t.obj")
    _tri(tmp_path / "t.glb")
    for ext, has in ((".obj", False), (".glb", True)):
        (tmp_path / "u.yaml").write_text(f"name: u\nobjects:\n  - name: t\n    mesh: t{ext}\n")
        geo = spec_to_dict(load_spec(tmp_path / "u.yaml"))["objects"][0]["geometry"]
        assert ("up_axis" in geo) == has, geo
    assert file_mesh(tmp_path / "t.glb", "y").vertices[2].tolist() == pytest.approx([0, 0, 2])
