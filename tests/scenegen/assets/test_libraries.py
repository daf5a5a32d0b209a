"""Asset library folders (scenegen.assets.libraries, docs/scene_spec.md "Asset libraries"): tiny
synthetic libraries in each layout (OBJ + MTL + PNG in ShapeNet's and Google Scanned Objects'
folders, a glb in an Objaverse-style folder) parsed, placed with their axis and scale
conventions (world bounds against trimesh's own reading of the file and the rotation written out
here), picked by seed, hostile ids refused with exit status 2, and rendered with their textures."""
import os
from pathlib import Path

import cv2
import numpy as np
import pytest
import trimesh
import yaml
from PIL import Image

from scenegen import api
from scenegen.assets import meshes
from scenegen.assets.libraries import LAYOUTS, LibraryError, library_file, pick_id
from scenegen.cli import main
from scenegen.errors import SpecError
from scenegen.geometry.color import linear_from_srgb
from scenegen.spec import load_spec, parse_spec, same_spec, spec_to_dict, to_yaml

SYNSET, CAR = "02958343", "1a0bc9ab92c915167ae33d942430658c"
GSO_NAME, UID = "Android_Figure_Panda", "8476c4170df24cf5bbe6967222d1a42d"
SHAPENET_SRGB, GSO_SRGB, GLB_SRGB = (200, 60, 40), (40, 180, 60), (50, 90, 210)
# the file's quads: ShapeNet (Y-up) at file y = 0.25, x in [-0.3, 0.3], z in [-0.2, 0.1];
# GSO (Z-up) at z = 0.1, x in [-0.2, 0.2], y in [-0.1, 0.3]; glb (Y-up) at y = 0, x, z in [0, 0.5]
SHAPENET_QUAD = [[-0.3, 0.25, 0.1], [0.3, 0.25, 0.1], [0.3, 0.25, -0.2], [-0.3, 0.25, -0.2]]
GSO_QUAD = [[-0.2, -0.1, 0.1], [0.2, -0.1, 0.1], [0.2, 0.3, 0.1], [-0.2, 0.3, 0.1]]
GLB_QUAD = [[0, 0, 0.5], [0.5, 0, 0.5], [0.5, 0, 0], [0, 0, 0]]
#: Y-up file -> our Z-up world, written out: +90 degrees about x, (x, y, z) -> (x, -z, y)
ROT_X90 = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])


def _png(path: Path, srgb) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), np.full((4, 4, 3), srgb[::-1], np.uint8))


def _obj(path: Path, quad, mtl: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    v = "".join(f"v {x} {y} {z}\n" for x, y, z in quad)
    # winding: the face's normal points up in the file's own up axis
    path.write_text(f"mtllib {mtl}\n{v}vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")


def write_shapenet(root: Path, model: str = CAR, synset: str = SYNSET, srgb=SHAPENET_SRGB) -> Path:
    """ShapeNetCore v2: <synset>/<model>/models/model_normalized.{obj,mtl}, the MTL naming
    ../images/texture0.png as ShapeNet's do."""
    m = root / synset / model
    _obj(m / "models/model_normalized.obj", SHAPENET_QUAD, "model_normalized.mtl")
    (m / "models/model_normalized.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd ../images/texture0.png\n")
    _png(m / "images/texture0.png", srgb)
    return m


def write_shapenet_v1(root: Path, model: str = CAR, synset: str = SYNSET) -> Path:
    """ShapeNetCore v1: <synset>/<model>/model.{obj,mtl}, the texture beside them."""
    m = root / synset / model
    _obj(m / "model.obj", SHAPENET_QUAD, "model.mtl")
    (m / "model.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd texture0.png\n")
    _png(m / "texture0.png", SHAPENET_SRGB)
    return m


def write_gso(root: Path, name: str = GSO_NAME) -> Path:
    """Google Scanned Objects as shipped: <name>/meshes/model.{obj,mtl}, the MTL naming
    'texture.png', which lies in materials/textures/ (not next to the MTL)."""
    m = root / name
    _obj(m / "meshes/model.obj", GSO_QUAD, "model.mtl")
    (m / "meshes/model.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd texture.png\n")
    _png(m / "materials/textures/texture.png", GSO_SRGB)
    return m


def write_objaverse(root: Path, uid: str = UID) -> Path:
    """An Objaverse-style folder: <uid>.glb (Y-up, a base colour texture, metallic 0, roughness 1)."""
    root.mkdir(parents=True, exist_ok=True)
    m = trimesh.Trimesh(vertices=GLB_QUAD, faces=[[0, 1, 2], [0, 2, 3]], process=False)
    mat = trimesh.visual.material.PBRMaterial(
        baseColorTexture=Image.fromarray(np.full((4, 4, 3), GLB_SRGB, np.uint8)), metallicFactor=0.0, roughnessFactor=1.0)
    m.visual = trimesh.visual.TextureVisuals(uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), material=mat)
    m.export(root / f"{uid}.glb")
    return root / f"{uid}.glb"


def libraries(tmp_path: Path) -> Path:
    write_shapenet(tmp_path / "ShapeNetCore.v2")
    write_shapenet_v1(tmp_path / "ShapeNetCore.v1")
    write_gso(tmp_path / "gso")
    write_objaverse(tmp_path / "objaverse")
    return tmp_path


def spec_text(mesh: dict, extra: str = "") -> str:
    return yaml.safe_dump({"name": "lib", "objects": [{"name": "a", "mesh": mesh}],
                           "cameras": {"cam": {"size": [32, 24], "fov_deg": 60}},
                           "views": [{"camera": "cam", "look_at": [{"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0]}]}]},
                          sort_keys=False) + extra


def _parse(tmp_path, mesh):
    return parse_spec(spec_text(mesh), file=str(tmp_path / "spec.yaml"), base_dir=tmp_path)


@pytest.mark.parametrize("layout, root, model_id, rot, scale, bounds", [
    # ShapeNet: file y (up) -> z, file -z (its front) -> +y; x2: z = 0.5, y in [-0.2, 0.4]
    ("shapenet", "ShapeNetCore.v2", f"{SYNSET}/{CAR}", ROT_X90, 2.0, [[-0.6, -0.2, 0.5], [0.6, 0.4, 0.5]]),
    ("shapenet_v1", "ShapeNetCore.v1", f"{SYNSET}/{CAR}", ROT_X90, 1.0, [[-0.3, -0.1, 0.25], [0.3, 0.2, 0.25]]),
    ("gso", "gso", GSO_NAME, np.eye(3), 1.0, [[-0.2, -0.1, 0.1], [0.2, 0.3, 0.1]]),  # Z-up metres: as stored
    ("objaverse", "objaverse", UID, ROT_X90, 0.5, [[0.0, -0.25, 0.0], [0.25, 0.0, 0.0]]),  # glTF floor -> z = 0
])
def test_each_layout_reads_its_file_with_its_axes_and_scale(tmp_path, layout, root, model_id, rot, scale, bounds):
    libraries(tmp_path)
    spec = _parse(tmp_path, {"library": layout, "root": root, "id": model_id, "scale": scale})
    g = spec.objects[0].geometry
    assert g.path == library_file(layout, tmp_path / root, model_id).path
    assert g.own_materials and g.up_axis == LAYOUTS[layout].up_axis
    local, _ = meshes.object_mesh(g)
    np.testing.assert_allclose(local.bounds, bounds, atol=1e-12)
    # independent: trimesh's own reading of the file, the rotation written out above, the scale
    raw = trimesh.load(str(g.path), force="mesh", process=False)
    np.testing.assert_allclose(local.vertices, (np.asarray(raw.vertices) @ rot.T) * scale, atol=1e-12)
    assert spec_to_dict(spec)["objects"][0]["geometry"]["library"] == {"layout": layout, "root": root, "id": model_id}
    assert same_spec(spec, parse_spec(to_yaml(spec), file="x.yaml", base_dir=tmp_path))


def _validate(tmp_path, mesh, capsys) -> tuple[int, str]:
    (tmp_path / "spec.yaml").write_text(spec_text(mesh))
    capsys.readouterr()
    rc = main(["validate", str(tmp_path / "spec.yaml")])
    return rc, capsys.readouterr().err


@pytest.mark.parametrize("mesh, words", [
    ({"library": "shapenet", "root": "ShapeNetCore.v2", "id": f"{SYNSET}/../../../etc"}, "plain names"),
    ({"library": "shapenet", "root": "ShapeNetCore.v2", "id": f"../{SYNSET}"}, "plain names"),
    ({"library": "gso", "root": "gso", "id": "/etc/passwd"}, "plain names"),
    ({"library": "gso", "root": "gso", "id": "http://example.com/x"}, "plain names"),
    ({"library": "gso", "root": "gso", "id": "a\\..\\b"}, "plain names"),
    ({"library": "gso", "root": "gso", "id": f"{GSO_NAME}/meshes"}, "1 part"),
    ({"library": "shapenet", "root": "ShapeNetCore.v2", "id": CAR}, "2 parts"),
    ({"library": "gso", "root": "gso", "id": "No_Such_Thing"}, "file not found"),
    ({"library": "gso", "root": "nowhere", "id": GSO_NAME}, "no such folder"),
    ({"library": "gso", "root": "gso", "id": "escape"}, "leaves the library root"),
    ({"library": "shapenet", "root": "ShapeNetCore.v2", "category": "..", "pick": 0}, "plain names"),
    ({"library": "shapenet", "root": "ShapeNetCore.v2", "category": SYNSET, "pick": 5}, "holds 1 model "),
    ({"library": "gso", "root": "gso", "category": "x"}, "has no categories"),
    ({"library": "shapenet", "root": "ShapeNetCore.v2", "id": f"{SYNSET}/{CAR}", "pick": 1}, "goes with 'category'"),
    ({"library": "blender", "root": "gso", "id": GSO_NAME}, "library layout"),
])
def test_hostile_ids_are_refused_with_file_line_and_exit_status_2(tmp_path, capsys, mesh, words):
    libraries(tmp_path)
    outside = tmp_path / "outside"
    write_gso(outside, "escape")
    os.symlink(outside / "escape", tmp_path / "gso" / "escape")  # a link out of the root
    rc, err = _validate(tmp_path, mesh, capsys)
    assert rc == 2, err
    line = err.strip().splitlines()[-1]
    assert line.startswith(f"scenegen: error: {tmp_path / 'spec.yaml'}:") and "objects[0].mesh." in line and words in line, line
    assert "Traceback" not in err


def test_a_shapenet_mtl_naming_a_file_outside_the_model_folder_is_refused(tmp_path, capsys):
    m = write_shapenet(tmp_path / "lib")
    (m / "models/model_normalized.mtl").write_text("newmtl m\nmap_Kd ../../../secret.png\n")
    _png(tmp_path / "secret.png", (1, 2, 3))
    rc, err = _validate(tmp_path, {"library": "shapenet", "root": "lib", "id": f"{SYNSET}/{CAR}"}, capsys)
    assert rc == 2 and "model_normalized.mtl:2: map_Kd '../../../secret.png': leaves" in err, err


def test_picks_by_seed_are_distinct_models_recorded_by_id(tmp_path):
    root = tmp_path / "lib"
    models = [f"{k:032x}" for k in range(6)]
    for mid in models:
        write_shapenet(root, mid)
    write_shapenet(root, "other", synset="03001627")
    picks = [pick_id("shapenet", root, SYNSET, k, 7) for k in range(6)]
    assert sorted(picks) == [f"{SYNSET}/{m}" for m in models]  # a permutation: all distinct
    assert picks == [pick_id("shapenet", root, SYNSET, k, 7) for k in range(6)]  # seeded
    assert picks != [pick_id("shapenet", root, SYNSET, k, 8) for k in range(6)]
    order = np.random.default_rng(7).permutation(6)  # the documented rule, written out
    assert picks == [f"{SYNSET}/{models[i]}" for i in order]
    objs = [{"name": f"car{k}", "mesh": {"library": "shapenet", "root": "lib", "category": SYNSET, "pick": k}}
            for k in range(3)]
    text = yaml.safe_dump({"name": "cars", "seed": 3, "objects": objs})
    spec = parse_spec(text, file="s.yaml", base_dir=tmp_path)
    ids = [o.geometry.library.id for o in spec.objects]
    assert len(set(ids)) == 3  # one seed for the category: picks 0, 1, 2 differ
    assert [spec_to_dict(spec)["objects"][k]["geometry"]["library"]["id"] for k in range(3)] == ids
    again = parse_spec(to_yaml(spec), file="s.yaml", base_dir=tmp_path)  # written back by id
    assert same_spec(spec, again)
    assert api.library_picks("shapenet", root, SYNSET, 3, seed=7) == tuple(picks[:3])


def test_the_python_api_builds_the_same_spec_as_the_yaml(tmp_path):
    libraries(tmp_path)
    spec = api.Scene("lib", base_dir=tmp_path, objects=[
        api.obj("a", api.library_mesh("shapenet", "ShapeNetCore.v2", f"{SYNSET}/{CAR}", scale=2.0))],
        cameras=[api.camera("cam", size=(32, 24), fov_deg=60)],
        views=[api.ViewSet(name=None, camera="cam", rig=None, placement=api.LookAtList(entries=(
            api.LookAt(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0)),)))])
    yaml_spec = _parse(tmp_path, {"library": "shapenet", "root": "ShapeNetCore.v2", "id": f"{SYNSET}/{CAR}", "scale": 2})
    assert spec_to_dict(spec)["objects"][0]["geometry"] == spec_to_dict(yaml_spec)["objects"][0]["geometry"]
    with pytest.raises(SpecError, match="library_mesh.id: .*plain names"):
        api.library_mesh("gso", "gso", "../x")
    with pytest.raises(SpecError, match="unknown library layout"):
        api.library_mesh("blender", "gso", "x")


def test_library_errors_name_the_key():
    with pytest.raises(LibraryError) as e:
        library_file("gso", Path("/nonexistent-root"), GSO_NAME)
    assert e.value.key == "root"


@pytest.mark.render
def test_a_model_of_each_layout_renders_its_own_texture(tmp_path, capsys):
    """Three library models side by side under a uniform white sky, seen from above: each
    object's mean linear colour over its inner pixels is its texture's (Lambertian OBJ texel within 5 %; the glTF's
    principled surface a x texel + b, a near 1, b small) and each lies where its axes put it."""
    from scenegen.dataset import Dataset
    libraries(tmp_path)
    objects = [
        {"name": "car", "mesh": {"library": "shapenet", "root": "ShapeNetCore.v2", "id": f"{SYNSET}/{CAR}"},
         "transform": {"translation": [-0.75, 0, -0.25]}},
        {"name": "panda", "mesh": {"library": "gso", "root": "gso", "id": GSO_NAME, "scale": 1.5},
         "transform": {"translation": [0, -0.15, 0]}},
        {"name": "thing", "mesh": {"library": "objaverse", "root": "objaverse", "id": UID},
         "transform": {"translation": [0.5, 0.25, 0]}},
    ]
    text = yaml.safe_dump({"name": "lib", "render": {"spp": 4}, "objects": objects,
                           "lights": [{"type": "constant", "radiance": 1.0}],
                           "cameras": {"cam": {"size": [32, 24], "fov_deg": 60}},
                           "views": [{"camera": "cam", "look_at": [{"eye": [0, 0, 2], "target": [0, 0, 0], "up": [0, 1, 0]}]}]},
                          sort_keys=False)
    (tmp_path / "lib.yaml").write_text(text)
    assert main(["render", str(tmp_path / "lib.yaml"), "-o", str(tmp_path / "out"), "--quiet"]) == 0, capsys.readouterr().err
    ds = Dataset(tmp_path / "out")
    view = ds.views[0]
    img, truth = ds.linear_image(view), ds.truth(view)
    texels = [linear_from_srgb(np.array(c) / 255.0) for c in (SHAPENET_SRGB, GSO_SRGB, GLB_SRGB)]
    for oid, texel in zip((1, 2, 3), texels):
        # inner pixels only (no background mixed in at the edges), averaged: the estimator is
        # unbiased but noisy at 4 spp, and a median of a skewed few dozen samples is not
        mask = cv2.erode((truth["object_id"] == oid).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
        assert mask.sum() >= 12, (oid, mask.sum())
        got = img[mask].mean(axis=0)
        print(f"object {oid}: {mask.sum()} inner pixels, rendered / texel {np.round(got / texel, 4).tolist()}")
        if oid < 3:  # measured 1.0045 (ShapeNet), 0.9852 (GSO)
            assert np.max(np.abs(got - texel) / texel) < 0.05, (oid, got, texel)
        else:
            a, b = np.polyfit(texel, got, 1)
            assert 0.95 < a < 1.15 and 0.0 <= b < 0.03, (a, b, got, texel)
    # the world meshes the dataset stores are where the axes put them (car at z = 0.25 - 0.25)
    car = trimesh.load(str(tmp_path / "out/scene/meshes/car.ply"), process=False)
    np.testing.assert_allclose(car.bounds, [[-1.05, -0.1, 0.0], [-0.45, 0.2, 0.0]], atol=1e-6)
