"""PBR texture sets in Poly Haven's naming (scenegen.assets.pbr_sets, `pbr_set:` on a principled
material): which file gives which map, the DirectX -> OpenGL normal conversion, errors at the
spec's file:line with exit status 2, and rendered: the diff colour is seen, a nor_dx set renders
as its nor_gl twin, and the normal map's green sign matters."""
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml

from scenegen.assets.pbr_sets import PbrSetError, find_set
from scenegen.cli import main
from scenegen.geometry.color import linear_from_srgb
from scenegen.geometry.conventions import opengl_from_directx_normal_map
from scenegen.spec import parse_spec, same_spec, to_yaml

DIFF_SRGB = (180, 140, 60)


def write_set(folder: Path, name="brick_wall_001", res="1k", maps=("diff", "nor_gl", "rough", "arm", "disp"),
              normal_rgb=(128, 128, 255), ext="jpg") -> Path:
    """A set of 8x8 one-colour maps (PNG for the normal maps: JPEG would round them)."""
    folder.mkdir(parents=True, exist_ok=True)
    colours = {"diff": DIFF_SRGB, "rough": (200, 200, 200), "arm": (255, 60, 30), "metal": (0, 0, 0),
               "disp": (128, 128, 128), "nor_gl": normal_rgb, "nor_dx": (normal_rgb[0], 255 - normal_rgb[1], normal_rgb[2])}
    for k in maps:
        suffix = "png" if k.startswith("nor") else ext
        assert cv2.imwrite(str(folder / f"{name}_{k}_{res}.{suffix}"), np.full((8, 8, 3), colours[k][::-1], np.uint8))
    return folder


def test_each_file_gives_its_map(tmp_path):
    s = find_set(write_set(tmp_path / "t"))
    assert (s.name, s.resolution) == ("brick_wall_001", "1k")
    assert s.base_color.name == "brick_wall_001_diff_1k.jpg"
    assert (s.roughness.path.name, s.roughness.channel) == ("brick_wall_001_rough_1k.jpg", 0)  # rough before arm
    assert (s.metallic.path.name, s.metallic.channel) == ("brick_wall_001_arm_1k.jpg", 2)  # arm's B
    assert (s.normal.path.name, s.normal.directx) == ("brick_wall_001_nor_gl_1k.png", False)
    s = find_set(write_set(tmp_path / "u", maps=("diff", "arm", "nor_dx")))
    assert (s.roughness.channel, s.metallic.channel, s.normal.directx) == (1, 2, True)  # arm's G, B; dx converted
    s = find_set(write_set(tmp_path / "v", maps=("diff", "nor_gl", "nor_dx")))
    assert not s.normal.directx  # nor_gl taken when both are there


def test_directx_normals_become_opengl_ones():
    # a normal tilted 30 degrees toward +v (down the image): DirectX stores n_y = +sin, OpenGL -sin
    n_gl = np.array([0.0, -0.5, np.sqrt(0.75)])
    n_dx = n_gl * [1, -1, 1]
    np.testing.assert_allclose(opengl_from_directx_normal_map((n_dx + 1) / 2), (n_gl + 1) / 2, atol=1e-7)


@pytest.mark.parametrize("maps, pbr, extra, words", [
    (("diff",), {"folder": "nowhere"}, {}, "no such folder"),
    (("rough",), {"folder": "t"}, {}, "no diff map"),
    (("diff",), {"folder": "t", "name": "other"}, {}, "no set 'other'"),
    (("diff",), {"folder": "t", "resolution": "4k"}, {}, "no 4k maps"),
    (("diff",), {"folder": "t", "disp_scale_m": 0.01}, {}, "no disp map"),
    (("diff",), {"folder": "t"}, {"texture": {"type": "image", "path": "t/brick_wall_001_diff_1k.jpg"}}, "exclude each other"),
    (("diff",), {"folder": "t", "nme": "x"}, {}, "unknown key 'nme'"),
])
def test_bad_sets_are_refused_with_file_line_and_exit_status_2(tmp_path, capsys, maps, pbr, extra, words):
    write_set(tmp_path / "t", maps=maps)
    spec = {"name": "s", "materials": {"m": {"type": "principled", "pbr_set": pbr, **extra}}}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(spec))
    capsys.readouterr()
    assert main(["validate", str(tmp_path / "s.yaml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"{tmp_path / 's.yaml'}:" in err and "materials.m." in err and words in err, err


def test_two_sets_or_an_exr_map_are_named(tmp_path):
    write_set(tmp_path / "t")
    write_set(tmp_path / "t", name="rock_02")
    with pytest.raises(PbrSetError, match="set names brick_wall_001, rock_02; give 'name'"):
        find_set(tmp_path / "t")
    write_set(tmp_path / "x", maps=("diff",))
    (tmp_path / "x/brick_wall_001_rough_1k.exr").write_bytes(b"v/1\x01")
    with pytest.raises(PbrSetError, match="rough_1k.exr: a exr map is not read"):
        find_set(tmp_path / "x")


def test_an_undecodable_map_fails_validate_at_the_sets_line(tmp_path, capsys):
    write_set(tmp_path / "t")
    (tmp_path / "t/brick_wall_001_rough_1k.jpg").write_bytes(b"not a jpeg")
    spec = {"name": "s", "materials": {"m": {"type": "principled", "pbr_set": {"folder": "t"}}},
            "objects": [{"name": "floor", "shape": "plane", "material": "m"}]}
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(spec))
    capsys.readouterr()
    assert main(["validate", str(tmp_path / "s.yaml")]) == 2
    err = capsys.readouterr().err
    assert f"{tmp_path / 's.yaml'}:" in err and "pbr_set" in err and "rough_1k.jpg" in err and "Traceback" not in err, err


def test_the_resolved_spec_records_the_set_and_round_trips(tmp_path):
    write_set(tmp_path / "t")
    text = yaml.safe_dump({"name": "s", "materials": {"m": {"type": "principled", "roughness": 0.3,
                                                              "pbr_set": {"folder": "t", "disp_scale_m": 0.002}}}})
    spec = parse_spec(text, file=str(tmp_path / "s.yaml"), base_dir=tmp_path)
    m = spec.materials["m"]
    assert m.texture.path.name == "brick_wall_001_diff_1k.jpg" and m.color is None
    assert m.pbr_set.disp.path.name == "brick_wall_001_disp_1k.jpg" and m.pbr_set.disp_scale_m == 0.002
    assert same_spec(spec, parse_spec(to_yaml(spec), file="x.yaml", base_dir=tmp_path))


def _render(tmp_path, folder: str, light: dict, capsys) -> tuple[np.ndarray, np.ndarray]:
    from scenegen.dataset import Dataset
    spec = {"name": folder, "render": {"spp": 4},
            "materials": {"m": {"type": "principled", "pbr_set": {"folder": folder}}},
            "objects": [{"name": "floor", "shape": {"type": "plane", "size": [3, 3]}, "material": "m"}],
            "lights": [light], "cameras": {"cam": {"size": [32, 24], "fov_deg": 40}},
            "views": [{"camera": "cam", "look_at": [{"eye": [0, 0, 2], "target": [0, 0, 0], "up": [0, 1, 0]}]}]}
    (tmp_path / f"{folder}.yaml").write_text(yaml.safe_dump(spec))
    out = tmp_path / f"out_{folder}"
    assert main(["render", str(tmp_path / f"{folder}.yaml"), "-o", str(out), "--quiet"]) == 0, capsys.readouterr().err
    ds = Dataset(out)
    return ds.linear_image(ds.views[0]), ds.truth(ds.views[0])["object_id"]


@pytest.mark.render
def test_a_set_renders_its_colour_and_its_normal_map_in_opengl_convention(tmp_path, capsys):
    tilt = (128, 64, 222)  # ~30 degrees: n_y = -0.5 in OpenGL's convention (down the image)
    write_set(tmp_path / "gl", maps=("diff", "rough", "nor_gl"), normal_rgb=tilt)
    write_set(tmp_path / "dx", maps=("diff", "rough", "nor_dx"), normal_rgb=tilt)
    write_set(tmp_path / "up", maps=("diff", "rough", "nor_gl"), normal_rgb=(128, 192, 222))
    write_set(tmp_path / "flat", maps=("diff", "rough", "nor_gl"))
    sky = {"type": "constant", "radiance": 1.0}
    img, ids = _render(tmp_path, "flat", sky, capsys)
    texel = linear_from_srgb(np.array(DIFF_SRGB) / 255.0)
    a, b = np.polyfit(texel, img[ids == 1].mean(axis=0), 1)  # principled: a x texel + a white b
    print(f"flat set under a white sky: a = {a:.4f}, b = {b:.4f}")
    assert 0.9 < a < 1.15 and 0.0 <= b < 0.06, (a, b)
    side = {"type": "directional", "direction_to_light": [0, 1, 1], "irradiance": 3.0}
    got = {k: _render(tmp_path, k, side, capsys)[0].mean() for k in ("gl", "dx", "up")}
    print(f"mean pixel under a light from +y: {got}")
    assert abs(got["gl"] - got["dx"]) < 1e-3 * got["gl"], got  # the converted DirectX map is the OpenGL one
    # and the green sign matters: the plane's texture is upright in this view (+v down the image,
    # world -y), so n_y > 0 (OpenGL: up the image) tilts toward the light at +y: cos 15 deg
    # against cos 75 deg, 3.7x (measured 4.2 with Mitsuba's bump-terminator shadowing)
    assert got["up"] > 3.0 * got["gl"], got


def test_the_python_api_builds_the_same_material_as_the_yaml(tmp_path):
    from scenegen import api
    from scenegen.errors import SpecError
    from scenegen.spec import spec_to_dict
    write_set(tmp_path / "t", maps=("diff", "arm", "nor_dx", "disp"))
    spec = api.Scene("s", base_dir=tmp_path, materials={"m": api.pbr_set_material("t", disp_scale_m=0.002, specular=0.3)},
                     objects=[api.obj("floor", api.Plane(), material="m")])
    text = yaml.safe_dump({"name": "s", "materials": {"m": {"type": "principled", "specular": 0.3,
                                                              "pbr_set": {"folder": "t", "disp_scale_m": 0.002}}},
                           "objects": [{"name": "floor", "shape": "plane", "material": "m"}]})
    parsed = parse_spec(text, file="s.yaml", base_dir=tmp_path)
    assert spec_to_dict(spec)["materials"] == spec_to_dict(parsed)["materials"]
    with pytest.raises(SpecError, match=r"materials.m.pbr_set.name: no set 'x'"):
        api.Scene("s", base_dir=tmp_path, materials={"m": api.pbr_set_material("t", name="x")})
