"""A user's own meshes with their own materials (OBJ/MTL + PNG, glTF PBR, vertex colours,
several materials per mesh), rendered as a new user would (spec file -> `scenegen render` ->
dataset) and compared with the colours the files say.

The scenes are lit by a uniform environment of radiance 1 and hold one flat, one-sided surface
facing the camera: a Lambertian surface of reflectance rho then has radiance exactly rho (linear),
so the linear image IS the reflectance, up to Monte Carlo noise.
"""
import cv2
import numpy as np
import pytest
import trimesh

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.errors import SpecError
from scenegen.geometry.color import linear_from_srgb
from scenegen.spec import load_spec

# Linear colour error allowed for a Lambertian texel under uniform light at 64 spp (measured
# 0.002-0.007, bilinear filtering at texel-block centres adds nothing).
TOL_LAMBERT_LINEAR = 0.015
# The four sRGB texel colours of the test texture (2x2 blocks of 4x4 texels), top-left first.
TEXELS = {"tl": (220, 40, 40), "tr": (40, 220, 40), "bl": (40, 40, 220), "br": (230, 230, 60)}

SCENE = """
name: own_{tag}
render: {{spp: 64, max_depth: 2}}
objects:
  - name: q
    mesh: {mesh}
{extra}lights:
  - {{type: constant, radiance: 1.0}}
cameras:
  cam: {{model: pinhole, size: [96, 64], fx: 60, fy: 60, cx: 47.5, cy: 31.5}}
views:
  - camera: cam
    look_at: [{{eye: [0, 0, 1.6], target: [0, 0, 0], up: [0, 1, 0]}}]
"""


def write_texture(folder):
    tex = np.zeros((8, 8, 3), np.uint8)
    tex[:4, :4], tex[:4, 4:] = TEXELS["tl"], TEXELS["tr"]
    tex[4:, :4], tex[4:, 4:] = TEXELS["bl"], TEXELS["br"]
    cv2.imwrite(str(folder / "tex.png"), tex[..., ::-1])
    return tex


def write_obj(folder, mtl_text=None):
    """Two unit quads side by side in z = 0 (x in [-1, 0]: material 'plain'; x in [0, 1]:
    'tex', UVs over the quad), normals +z."""
    (folder / "quad.mtl").write_text(mtl_text or "newmtl plain\nKd 0.2 0.5 0.7\n"
                                                 "newmtl tex\nKd 1 1 1\nmap_Kd tex.png\n")
    (folder / "quad.obj").write_text(
        "mtllib quad.mtl\n"
        "v -1 -0.5 0\nv 0 -0.5 0\nv 0 0.5 0\nv -1 0.5 0\nv 0 -0.5 0\nv 1 -0.5 0\nv 1 0.5 0\nv 0 0.5 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "usemtl plain\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
        "usemtl tex\nf 5/1 6/2 7/3\nf 5/1 7/3 8/4\n")
    return folder / "quad.obj"


def write_glb(folder, tex, **pbr):
    from PIL import Image

    # glTF is Y-up: the quad x in [0, 1], y in [-0.5, 0.5] of our z = 0 plane is (x, 0, -y) in the file
    m = trimesh.Trimesh(vertices=[[0, 0, 0.5], [1, 0, 0.5], [1, 0, -0.5], [0, 0, -0.5]],
                        faces=[[0, 1, 2], [0, 2, 3]], process=False)
    mat = trimesh.visual.material.PBRMaterial(baseColorTexture=Image.fromarray(tex), **pbr)
    m.visual = trimesh.visual.TextureVisuals(uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), material=mat)
    m.export(folder / "quad.glb")
    return folder / "quad.glb"


def render(folder, tag, mesh, extra="", capsys=None):
    spec = folder / f"{tag}.yaml"
    spec.write_text(SCENE.format(tag=tag, mesh=mesh, extra=extra))
    assert main(["render", str(spec), "-o", str(folder / f"out_{tag}"), "--no-progress"]) == 0
    ds = Dataset(folder / f"out_{tag}")
    return ds, ds.linear_image(ds.views[0]), ds.truth(ds.views[0])


def pixel(x, y):
    """(row, col) of the world point (x, y, 0) in the test camera (eye at z = 1.6, f = 60 px)."""
    return round(31.5 - y * 60 / 1.6), round(47.5 + x * 60 / 1.6)


def texel_pixels(x0):
    """Pixels at the centres of the texture's four blocks on the quad x in [x0, x0 + 1]."""
    return {"tl": pixel(x0 + 0.25, 0.25), "tr": pixel(x0 + 0.75, 0.25),
            "bl": pixel(x0 + 0.25, -0.25), "br": pixel(x0 + 0.75, -0.25)}


def expected_linear(name):
    return linear_from_srgb(np.array(TEXELS[name]) / 255.0)


@pytest.mark.render
def test_obj_mtl_with_its_png_renders_its_own_colours(tmp_path, capsys):
    write_texture(tmp_path)
    write_obj(tmp_path)
    ds, img, truth = render(tmp_path, "obj", "quad.obj")
    assert "warning" not in capsys.readouterr().err
    errs = [np.abs(img[pixel(-0.5, 0)] - np.array([0.2, 0.5, 0.7])).max()]
    for name, (r, c) in texel_pixels(0.0).items():
        errs.append(np.abs(img[r, c] - expected_linear(name)).max())
    print(f"OBJ/MTL colour error (linear, max abs over 5 colours): {max(errs):.4f}")
    assert max(errs) < TOL_LAMBERT_LINEAR, errs
    # both parts are the one object: one object id, one instance id
    assert set(np.unique(truth["object_id"][truth["valid"]])) == {1}
    assert set(np.unique(truth["instance_id"][truth["valid"]])) == {1}
    # the stored world mesh is the whole file (8 vertices, 4 faces)
    assert len(ds.mesh("q").faces) == 4


@pytest.mark.render
def test_gltf_base_color_texture_and_factor(tmp_path):
    """A glTF's PBR material renders through Mitsuba's principled BSDF, which is linear in the base
    colour: L(c) = L(0) + c (L(1) - L(0)) per pixel. L(0), L(1) come from the same mesh with a
    spec principled material of base colour 0 and 1 (same geometry, same samples), so the glTF
    colours must be the texture's texels times baseColorFactor."""
    tex = write_texture(tmp_path)
    factor = (1.0, 0.8, 0.6, 1.0)
    write_glb(tmp_path, tex, baseColorFactor=factor, metallicFactor=0.0, roughnessFactor=0.7)
    _, img, _ = render(tmp_path, "glb", "quad.glb")
    refs = {}
    for c in (0, 1):
        mat = f"    material: {{type: principled, color: {c}, roughness: 0.7}}\n"
        refs[c] = render(tmp_path, f"ref{c}", "quad.glb", mat)[1]
    errs, lambert = [], []
    for name, (r, cc) in texel_pixels(0.0).items():
        want_rho = expected_linear(name) * np.array(factor[:3])
        want = refs[0][r, cc] + want_rho * (refs[1][r, cc] - refs[0][r, cc])
        errs.append(np.abs(img[r, cc] - want).max())
        lambert.append(np.abs(img[r, cc] - want_rho).max())
    print(f"glTF colour error vs principled(base colour) (linear): {max(errs):.4f}; "
          f"vs a Lambertian surface of that colour: {max(lambert):.4f}")
    assert max(errs) < TOL_LAMBERT_LINEAR, errs


@pytest.mark.render
def test_spec_material_overrides_the_files_and_says_so(tmp_path, capsys):
    write_texture(tmp_path)
    write_obj(tmp_path)
    _, img, _ = render(tmp_path, "ovr", "quad.obj", "    material: {type: diffuse, color: [0.3, 0.3, 0.3]}\n")
    err = capsys.readouterr().err
    assert "has its own materials (plain, tex)" in err and "replaces them" in err
    for x in (-0.5, 0.25, 0.75):
        assert np.abs(img[pixel(x, 0.25)] - 0.3).max() < TOL_LAMBERT_LINEAR


@pytest.mark.render
def test_vertex_colours(tmp_path):
    m = trimesh.Trimesh(vertices=[[-1, -0.5, 0], [1, -0.5, 0], [1, 0.5, 0], [-1, 0.5, 0]],
                        faces=[[0, 1, 2], [0, 2, 3]], process=False,
                        vertex_colors=np.array([[200, 120, 30, 255]] * 4, np.uint8))
    m.export(tmp_path / "vc.ply")
    _, img, _ = render(tmp_path, "vc", "vc.ply")
    want = linear_from_srgb(np.array([200, 120, 30]) / 255.0)
    err = np.abs(img[pixel(0.1, 0.1)] - want).max()
    print(f"vertex colour error (linear): {err:.4f}")
    assert err < TOL_LAMBERT_LINEAR


def test_a_mesh_without_materials_keeps_its_form_and_hash(tmp_path):
    """No MTL: the resolved spec is what it always was (no `files`, no `own_materials`)."""
    from scenegen.spec.serialize import spec_to_dict

    (tmp_path / "plain.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    spec_path = tmp_path / "p.yaml"
    spec_path.write_text("name: p\nobjects:\n  - {name: m, mesh: plain.obj}\n")
    spec = load_spec(spec_path)
    assert not spec.objects[0].geometry.own_materials
    assert spec_to_dict(spec)["objects"][0]["geometry"] == {
        "path": {"path": "plain.obj", "sha256": spec_to_dict(spec)["objects"][0]["geometry"]["path"]["sha256"]},
        "kind": "mesh"}


def test_the_files_an_obj_names_are_hashed(tmp_path):
    from scenegen.spec.serialize import spec_to_dict

    write_texture(tmp_path)
    write_obj(tmp_path)
    spec_path = tmp_path / "o.yaml"
    spec_path.write_text("name: o\nobjects:\n  - {name: m, mesh: quad.obj}\n")
    geo = spec_to_dict(load_spec(spec_path))["objects"][0]["geometry"]
    assert geo["own_materials"] is True
    assert [f["path"]["path"] for f in geo["files"]] == ["quad.mtl", "tex.png"]


@pytest.mark.parametrize("line,want", [
    ("map_Kd ../outside.png", "leaves the asset's folder"),
    ("map_Kd /etc/passwd", "no absolute path"),
    ("map_Kd missing.png", "file not found"),
    ("map_Kd http://example.com/t.png", "no absolute path or URL"),
    ("Kd 0.5 red 0.1", "expected 1 or 3 number(s) in [0, 1]"),
    ("d 1.5", "expected 1 number(s) in [0, 1]"),
])
def test_bad_names_in_an_mtl_name_the_file_and_line(tmp_path, line, want):
    sub = tmp_path / "asset"
    sub.mkdir()
    (tmp_path / "outside.png").write_bytes(b"x")
    write_obj(sub, f"newmtl plain\nKd 1 1 1\n\nnewmtl tex\n{line}\n")
    spec_path = tmp_path / "bad.yaml"
    spec_path.write_text("name: b\nobjects:\n  - {name: m, mesh: asset/quad.obj}\n")
    with pytest.raises(SpecError) as e:
        load_spec(spec_path)
    assert str(e.value).startswith(f"{sub / 'quad.mtl'}:5: {line.split()[0]}"), str(e.value)
    assert want in str(e.value) and "objects[0].mesh" in str(e.value)


def test_a_gltf_uri_outside_its_folder_is_refused(tmp_path):
    sub = tmp_path / "asset"
    sub.mkdir()
    (sub / "m.gltf").write_text('{"asset": {"version": "2.0"},\n "buffers": [\n  {"uri": "../../x.bin", '
                                '"byteLength": 4}]}\n')
    spec_path = tmp_path / "g.yaml"
    spec_path.write_text("name: g\nobjects:\n  - {name: m, mesh: asset/m.gltf}\n")
    with pytest.raises(SpecError, match=r"m.gltf:3: buffers\[0\].uri '../../x.bin': leaves"):
        load_spec(spec_path)


@pytest.mark.render
def test_gltf_normal_texture_is_the_spec_normal_map(tmp_path):
    """glTF's normalTexture (+y up the image) is the spec's `normal_map` convention, unflipped:
    the glTF renders exactly as the same mesh with a spec principled material and that map."""
    from PIL import Image

    n = np.array([0.3, 0.45, 0.0])
    n[2] = np.sqrt(1 - n @ n)
    nmap = np.tile(np.round((n + 1) / 2 * 255).astype(np.uint8), (4, 4, 1))
    cv2.imwrite(str(tmp_path / "n.png"), nmap[..., ::-1])
    tex = write_texture(tmp_path)
    write_glb(tmp_path, tex, metallicFactor=0.0, roughnessFactor=0.6, normalTexture=Image.fromarray(nmap))
    lights = "lights:\n  - {type: point, position: [-2, 3, 6], intensity: 40}\n"
    glb, ref = [], []
    spec_mat = ("    material: {type: principled, texture: {type: image, path: tex.png}, "
                "roughness: 0.6, normal_map: n.png}\n")
    for tag, extra, out in (("gn", "", glb), ("gs", spec_mat, ref)):
        text = SCENE.format(tag=tag, mesh="quad.glb", extra=extra).replace(
            "lights:\n  - {type: constant, radiance: 1.0}\n", lights)
        (tmp_path / f"{tag}.yaml").write_text(text)
        assert main(["render", str(tmp_path / f"{tag}.yaml"), "-o", str(tmp_path / tag), "-q"]) == 0
        ds = Dataset(tmp_path / tag)
        out.append(ds.linear_image(ds.views[0]))
    np.testing.assert_allclose(glb[0], ref[0], atol=1e-6)


@pytest.mark.render
def test_gltf_alpha_mask_truth_follows_the_holes(tmp_path):
    """alphaMode MASK: texels under alphaCutoff are holes in the image AND in the truth."""
    from PIL import Image

    rgba = np.zeros((4, 4, 4), np.uint8)
    rgba[..., 0] = 230
    rgba[..., 3] = 255
    rgba[::2, ::2, 3] = rgba[1::2, 1::2, 3] = 20  # holes (alpha 0.08 < cutoff 0.5)
    # in z = 0.4 of our world; glTF is Y-up, so the file holds (x, 0.4, -y)
    m = trimesh.Trimesh(vertices=[[-1, 0.4, 0.5], [1, 0.4, 0.5], [1, 0.4, -0.5], [-1, 0.4, -0.5]],
                        faces=[[0, 1, 2], [0, 2, 3]], process=False)
    mat = trimesh.visual.material.PBRMaterial(baseColorTexture=Image.fromarray(rgba, "RGBA"),
                                              alphaMode="MASK", alphaCutoff=0.5, metallicFactor=0.0)
    m.visual = trimesh.visual.TextureVisuals(uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]), material=mat)
    m.export(tmp_path / "mask.glb")
    extra = ("  - name: back\n    shape: {type: plane, size: [4, 3]}\n"
             "    material: {type: diffuse, color: [0.05, 0.05, 0.8]}\n")
    _, img, truth = render(tmp_path, "mask", "mask.glb", extra)
    oid = truth["object_id"]
    assert set(np.unique(oid)) == {1, 2}
    # wherever a pixel's whole 3x3 neighbourhood sees one surface (texel edges do not fall on
    # pixel edges here, and the image averages over the pixel), the image shows the truth's surface
    pad = np.pad(oid, 1, mode="edge")
    shifts = [pad[1 + dr:1 + dr + oid.shape[0], 1 + dc:1 + dc + oid.shape[1]]
              for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
    interior = np.all([sh == oid for sh in shifts], axis=0)
    assert interior.mean() > 0.8
    np.testing.assert_array_equal((oid == 1)[interior], (img[..., 0] > img[..., 2])[interior])
    # the pattern: quad texel (i, j) covers x in [-1 + j/2, -1 + (j+1)/2], y in [0.5 - (i+1)/4, 0.5 - i/4]
    for i in range(4):
        for j in range(4):
            r, c = pixel((-1 + (j + 0.5) / 2) * 1.6 / 1.2, (0.5 - (i + 0.5) / 4) * 1.6 / 1.2)  # z = 0.4
            assert oid[r, c] == (2 if rgba[i, j, 3] < 128 else 1), (i, j)


@pytest.mark.render
def test_mtl_specular_and_emission(tmp_path, capsys):
    """Ks/Ns (roughplastic) and Ke (an area emitter on the part) render: the emissive part's
    radiance is its Ke plus its reflection (no light in the scene but the constant one at 0)."""
    write_texture(tmp_path)
    write_obj(tmp_path, "newmtl plain\nKd 0.2 0.5 0.7\nKs 0.5 0.5 0.5\nNs 80\n"
                        "newmtl tex\nKd 0 0 0\nKe 0.3 0.6 0.9\n")
    _, img, _ = render(tmp_path, "emis", "quad.obj")
    np.testing.assert_allclose(img[pixel(0.5, 0)], [0.3, 0.6, 0.9], atol=1e-3)


@pytest.mark.render
def test_gltf_with_two_meshes_keeps_each_material(tmp_path):
    """A glTF scene of two meshes (two materials, node transforms): each part its own colour, one
    object id, and the dataset's world mesh is the whole flattened file."""
    from scenegen.assets.meshes import file_mesh

    def quad(x0, rgb):
        # glTF is Y-up: (x, 0, -y) in the file is (x, y, 0) in our world
        m = trimesh.Trimesh(vertices=[[0, 0, 0.5], [1, 0, 0.5], [1, 0, -0.5], [0, 0, -0.5]],
                            faces=[[0, 1, 2], [0, 2, 3]], process=False)
        m.visual = trimesh.visual.TextureVisuals(
            uv=np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]]),
            material=trimesh.visual.material.PBRMaterial(baseColorFactor=[*rgb, 1.0], metallicFactor=0.0,
                                                         roughnessFactor=0.7))
        return m, trimesh.transformations.translation_matrix([x0, 0, 0])

    scene = trimesh.Scene()
    for name, (m, T) in (("left", quad(-1.0, (0.8, 0.2, 0.1))), ("right", quad(0.0, (0.1, 0.3, 0.8)))):
        scene.add_geometry(m, node_name=name, geom_name=name, transform=T)
    scene.export(tmp_path / "two.glb")
    ds, img, truth = render(tmp_path, "two", "two.glb")
    a, b = img[pixel(-0.5, 0)], img[pixel(0.5, 0)]
    assert a[0] > 3 * a[2] and b[2] > 2 * b[0]  # red left, blue right
    assert set(np.unique(truth["object_id"][truth["valid"]])) == {1}
    stored = ds.mesh("q")
    np.testing.assert_allclose(np.asarray(stored.vertices), file_mesh(tmp_path / "two.glb", "y").vertices, atol=1e-6)
    np.testing.assert_allclose(np.asarray(stored.vertices)[:, 2], 0.0, atol=1e-6)  # Y-up file, our z = 0


def test_colour_variation_of_a_mesh_with_its_own_materials_is_refused(tmp_path):
    write_texture(tmp_path)
    write_obj(tmp_path)
    spec_path = tmp_path / "v.yaml"
    spec_path.write_text("name: v\nobjects:\n  - {name: m, mesh: quad.obj}\n"
                         "variation:\n  objects:\n    m: {color: {min: [0.1, 0.1, 0.1], max: [0.9, 0.9, 0.9]}}\n")
    with pytest.raises(SpecError, match="renders its mesh file's own materials"):
        load_spec(spec_path)


@pytest.mark.render
def test_a_moving_mesh_with_its_own_materials_blurs_every_part(tmp_path):
    """Object motion moves every part (one Mitsuba mesh per material): the render of the
    two-material OBJ is blurred across the parts' border, and the truth (mid-exposure pose) is
    that of the still object."""
    write_texture(tmp_path)
    write_obj(tmp_path)
    motion = "    motion: {linear_velocity_mps: [20, 0, 0]}\n"
    cams = SCENE.format(tag="mv", mesh="quad.obj", extra=motion).replace(
        "cam: {model: pinhole,", "cam: {shutter: {exposure_s: 0.01}, model: pinhole,")
    (tmp_path / "mv.yaml").write_text(cams.replace("render: {spp: 64, max_depth: 2}",
                                                   "render: {spp: 16, max_depth: 2, motion_subframes: 4}"))
    assert main(["render", str(tmp_path / "mv.yaml"), "-o", str(tmp_path / "mv"), "-q"]) == 0
    _, still, still_truth = render(tmp_path, "still", "quad.obj")
    ds = Dataset(tmp_path / "mv")
    moved, truth = ds.linear_image(ds.views[0]), ds.truth(ds.views[0])
    np.testing.assert_array_equal(truth["object_id"], still_truth["object_id"])
    # 0.2 m of travel over the exposure (7.5 px): the plain/textured border is smeared
    r, c = pixel(0.0, 0.25)
    assert not np.allclose(moved[r, c - 3:c + 4], still[r, c - 3:c + 4], atol=0.05)
