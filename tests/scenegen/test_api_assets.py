"""The Python API with a user's own assets and a sequence (docs/python_api.md, "Your own meshes"):
the documented block runs as written on an OBJ/MTL/PNG and a Y-up glTF, and the rendered colours
are the textures'; meshes given as paths, hand-built mesh records, materials, light names and
warnings that name fields."""
import dataclasses
import json
import re
from pathlib import Path

import cv2
import numpy as np
import pytest
import trimesh
from PIL import Image

from scenegen import api
from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.errors import SpecError
from scenegen.geometry.color import linear_from_srgb

ROOT = Path(__file__).resolve().parents[2]
CRATE_SRGB = (200, 120, 40)
LAMP_SRGB = (40, 110, 190)


def write_assets(folder: Path) -> None:
    """assets/crate.obj (a quad in z = 0 facing +z, its MTL's map_Kd a one-colour PNG, Kd 1) and
    assets/lamp.glb (Y-up as glTF says: a quad on the glTF floor, the xz plane, facing +Y; a
    base colour texture of one colour, metallic 0, roughness 1)."""
    a = folder / "assets"
    a.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(a / "crate.png"), np.full((4, 4, 3), CRATE_SRGB[::-1], np.uint8))
    (a / "crate.mtl").write_text("newmtl wood\nKd 1 1 1\nmap_Kd crate.png\n")
    (a / "crate.obj").write_text("mtllib crate.mtl\nv -0.5 -0.4 0\nv 0.1 -0.4 0\nv 0.1 0.4 0\nv -0.5 0.4 0\n"
                                 "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl wood\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")
    m = trimesh.Trimesh(vertices=[[0, 0, 0.4], [0.5, 0, 0.4], [0.5, 0, -0.4], [0, 0, -0.4]],
                        faces=[[0, 1, 2], [0, 2, 3]], process=False)
    mat = trimesh.visual.material.PBRMaterial(baseColorTexture=Image.fromarray(np.full((4, 4, 3), LAMP_SRGB, np.uint8)),
                                              metallicFactor=0.0, roughnessFactor=1.0)
    m.visual = trimesh.visual.TextureVisuals(uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), material=mat)
    m.export(a / "lamp.glb")


def documented_block() -> str:
    blocks = re.findall(r"```python\n(.*?)```", (ROOT / "docs/python_api.md").read_text(), re.S)
    return next(b for b in blocks if '"my_assets"' in b)


@pytest.mark.render
def test_the_documented_stereo_sequence_with_own_obj_and_gltf_renders_their_textures(tmp_path, monkeypatch, capsys):
    write_assets(tmp_path)
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    exec(compile(documented_block(), "docs/python_api.md", "exec"), ns)
    assert ns["summary"].views_rendered == 6
    assert ns["spec"].warnings == ()
    ds = Dataset(tmp_path / "out/my_assets")
    assert [v for v in ds.views] == [f"stereo_{s}_{k:04d}" for k in range(3) for s in ("left", "right")]
    crate, lamp = (linear_from_srgb(np.array(c) / 255.0) for c in (CRATE_SRGB, LAMP_SRGB))
    crate_err, lamp_fit = [], []
    for view in ds.views:
        img, truth = ds.linear_image(view), ds.truth(view)
        masks = {oid: truth["object_id"] == oid for oid in (1, 2)}
        assert min(m.sum() for m in masks.values()) > 300, view  # both quads face the camera
        got_crate, got_lamp = (np.median(img[masks[oid]], axis=0) for oid in (1, 2))
        # Lambertian under uniform radiance 1: the linear pixel is the texel's reflectance
        crate_err.append(np.max(np.abs(got_crate - crate) / crate))
        # Mitsuba's principled BSDF (metallic 0, roughness 1) is base colour x a + a white
        # specular b: the three channels must lie on that line, with a near 1 and b small
        a, b = np.polyfit(lamp, got_lamp, 1)
        lamp_fit.append((a, b, np.max(np.abs(a * lamp + b - got_lamp))))
    print(f"OBJ texel relative error (worst channel, 6 views): {max(crate_err):.3f}; glTF fit "
          f"(a, b, residual): {np.round(lamp_fit, 4).tolist()}")
    assert max(crate_err) < 0.05, crate_err  # measured 0.032 at 4 spp
    for a, b, resid in lamp_fit:
        assert 0.95 < a < 1.15 and 0.0 <= b < 0.03 and resid < 0.006, (a, b, resid)
    # `scenegen info` names the scene, its clock and the truth it holds
    capsys.readouterr()
    assert main(["info", "out/my_assets", "--limit", "1"]) == 0
    out = capsys.readouterr().out
    assert "scene 'my_assets'" in out and "sequence: 3 frames at 10 fps, t = 0 .. 0.2 s; flow steps 1" in out
    assert "truth per view: depth_z, instance_id, normals_cam" in out and "sequence truth: flow, motion, object poses" in out
    assert main(["info", "out/my_assets", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["scene"] == "my_assets" and doc["sequence"]["timestamps_s"] == [0.0, 0.1, 0.2]
    assert "object_id" in doc["truth"]["view"] and doc["truth"]["sequence"] == ["flow", "motion", "object poses"]
    # the glTF's floor (its xz plane, +Y up) is our z = 0 plane; frame 0 places it at x + 0.2
    v = ds.mesh("lamp").vertices
    np.testing.assert_allclose(v[:, 2], 0.0, atol=1e-7)
    np.testing.assert_allclose(sorted(set(np.round(v[:, 0], 6))), [0.2, 0.7], atol=1e-6)


def test_a_mesh_as_a_path_and_a_hand_built_mesh_record_resolve_like_the_yaml(tmp_path):
    write_assets(tmp_path)
    by_path = api.obj("crate", tmp_path / "assets/crate.obj")  # a PosixPath
    by_hand = api.obj("lamp", api.Mesh(path=Path("assets/lamp.glb"), path_as_written="assets/lamp.glb",
                                       files=None, up_axis="y"))
    spec = api.Scene(objects=[by_path, by_hand], base_dir=tmp_path)
    crate, lamp = (o.geometry for o in spec.objects)
    assert crate.own_materials and lamp.own_materials and crate.up_axis == "z" and lamp.up_axis == "y"
    assert [f.path_as_written for f in crate.files] == ["crate.mtl", "crate.png"]
    assert api.same_spec(spec, api.Scene(objects=[api.obj("crate", str(tmp_path / "assets/crate.obj")),
                                                  api.obj("lamp", api.mesh("assets/lamp.glb"))], base_dir=tmp_path))


def test_a_material_replaces_the_files_own_and_the_warning_names_the_field_not_a_yaml_line(tmp_path):
    write_assets(tmp_path)
    red = api.DiffuseMaterial(color=(0.8, 0.1, 0.1))
    spec = api.Scene(objects=[api.obj("crate", "assets/crate.obj", material=red)], base_dir=tmp_path)
    assert not spec.objects[0].geometry.own_materials
    assert spec.objects[0].material.color == (0.8, 0.1, 0.1)
    (w,) = spec.warnings
    assert w.startswith("<python>: objects[0].material: the mesh 'assets/crate.obj' has its own materials"), w


def test_image_textures_resolve_against_base_dir_and_a_missing_file_names_its_field(tmp_path):
    write_assets(tmp_path)
    mat = api.DiffuseMaterial(texture=api.image_texture("assets/crate.png"))
    spec = api.Scene(objects=[api.obj("ball", api.Sphere(radius=0.2), material=mat)], base_dir=tmp_path)
    assert spec.objects[0].material.texture.path == (tmp_path / "assets/crate.png").resolve()
    bare = api.DiffuseMaterial(texture=api.Texture(kind="image", path=Path("assets/crate.png")))  # no path_as_written
    spec = api.Scene(objects=[api.obj("ball", api.Sphere(radius=0.2), material=bare)], base_dir=tmp_path)
    assert spec.objects[0].material.texture.path == (tmp_path / "assets/crate.png").resolve()
    with pytest.raises(SpecError, match=r"^<python>: objects\[0\]\.mesh: file not found: 'nope.obj'"):
        api.Scene(objects=[api.obj("x", "nope.obj")], base_dir=tmp_path)


def test_a_sequence_places_animated_objects_and_trajectory_views_on_its_clock(tmp_path):
    traj = api.trajectory([api.keyframe(0.0, translation=(0, 0, 0)), api.keyframe(1.0, translation=(1, 0, 0))],
                          "linear")
    spec = api.Scene(sequence=api.sequence(fps=4, frames=3, start_s=0.5),
                     objects=[api.obj("ball", api.Sphere(radius=0.2)),
                              api.obj("box", api.Box(size=(0.2, 0.2, 0.2)), trajectory=traj)],
                     lights=[api.ConstantLight(radiance=(1.0, 1.0, 1.0))],
                     cameras=[api.camera("cam", size=(32, 24), fov_deg=60)],
                     views=[api.ViewSet(name=None, camera="cam", rig=None, placement=api.trajectory(
                         [api.keyframe(0.0, eye=(0, -3, 1), target=(0, 0, 0)),
                          api.keyframe(2.0, eye=(1, -3, 1), target=(0, 0, 0))]))])
    assert spec.sequence.timestamps_s == (0.5, 0.75, 1.0)
    assert spec.lights[0].name == "light0"
    np.testing.assert_allclose(spec.objects[1].transform.world_from_object.t, [0.5, 0, 0])  # at frame 0 (0.5 s)
    assert spec.view_sets[0].placement.times_s == (0.5, 0.75, 1.0)
    assert api.same_spec(spec, api.check_spec(spec))
    with pytest.raises(SpecError, match="give fps and frames, or timestamps_s"):
        api.sequence(fps=4)


def test_a_multi_rig_and_a_stereo_rig_are_the_yaml_ones():
    cams = [api.camera("a", size=(32, 24), fov_deg=60), api.camera("b", size=(32, 24), fov_deg=60)]
    rig = api.stereo_rig("st", "a", "b", baseline_m=0.2, vergence_deg=4.0)
    spec = api.Scene(cameras=cams, rigs=[rig], views=[api.ViewSet(name=None, camera=None, rig="st",
                                                                  placement=api.Orbit(radius_m=2, count=2))])
    right = spec.rigs["st"].members[1].rig_from_cam
    np.testing.assert_allclose(right.t, [0.2, 0, 0])
    assert np.degrees(np.arccos(right.R[0, 0])) == pytest.approx(2.0)
    assert dataclasses.replace(rig, baseline_m=0.2).baseline_m == 0.2
