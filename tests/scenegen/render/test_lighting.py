"""Per-view-set lighting (`lights:` on a view set): parsing, hashing, variants, rendering, truth
and cameras.json. An illumination series keeps the geometry and changes only the lights."""
from __future__ import annotations

import json

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.spec import parse_spec, resolve_views, spec_sha256, spec_to_dict
from scenegen.spec.views import light_scales_dict

# Scaling one light by a power of two is exact: every sample's contribution is multiplied by 2,
# which commutes with float rounding, and Mitsuba picks emitters by their sampling weight, not
# by power, so the same paths are traced. The images must agree bit for bit.
TOL_POWER_OF_TWO_SCALE = 0.0
# Superposition (three lights on, non-power-of-two factors): the same paths again, but each
# contribution is rounded differently (float32, a few operations per bounce, 16 samples summed):
# a few float32 ulps (6e-8) of the pixel value. Relative to the pixel, with a floor at 1e-6 of
# the image maximum for nearly black pixels.
TOL_SUPERPOSITION_REL = 2e-6

SCENE = """
name: lit
render: {spp: 8, max_depth: 3, sampler: ldsampler}
objects:
  - name: floor
    shape: {type: plane, size: [4, 4]}
    material: {type: diffuse, texture: {type: noise, params: {size_px: 64}}}
  - name: ball
    shape: {type: sphere, radius: 0.4}
    transform: {translation: [0, 0, 0.4]}
    material: {type: plastic, color: [0.6, 0.2, 0.1], roughness: 0.2}
lights:
  - {type: point, name: bulb, position: [1, -1, 2], intensity: 3}
  - {type: area, name: panel, size: [0.6, 0.6], position: [-1.5, -0.5, 1.5], look_at: [0, 0, 0.3], radiance: 4}
  - {type: constant, name: sky, radiance: 0.1}
cameras:
  cam: {size: [120, 90], fov_deg: 50}
views:
  - name: ref
    camera: cam
    lights: [bulb, sky]
    look_at: [{eye: [0, -3, 2], target: [0, 0, 0.3]}]
  - name: light
    camera: cam
    lights: {panel: 1.5, sky: 0.5}
    look_at: [{eye: [0, -3, 2], target: [0, 0, 0.3]}]
  - name: light
    camera: cam
    lights: {bulb: 2}
    look_at: [{eye: [0, -3, 2], target: [0, 0, 0.3]}]
  - name: all
    camera: cam
    look_at: [{eye: [0, -3, 2], target: [0, 0, 0.3]}]
"""


def test_parsed_scales_per_view():
    spec = parse_spec(SCENE)
    assert [dict(vs.lights) if vs.lights is not None else None for vs in spec.view_sets] == [
        {"bulb": 1.0, "panel": 0.0, "sky": 1.0},  # a list: named lights on, the others off
        {"bulb": 0.0, "panel": 1.5, "sky": 0.5},  # a mapping: unnamed lights off
        {"bulb": 2.0, "panel": 0.0, "sky": 0.0},
        None]
    views = resolve_views(spec)
    assert [v.name for v in views] == ["ref_0000", "light_0001", "light_0002", "all_0003"]
    assert [v.light_scales for v in views] == [(1.0, 0.0, 1.0), (0.0, 1.5, 0.5), (2.0, 0.0, 0.0), None]
    assert light_scales_dict(spec, None) == {"bulb": 1.0, "panel": 1.0, "sky": 1.0}
    assert light_scales_dict(spec, views[1].light_scales) == {"bulb": 0.0, "panel": 1.5, "sky": 0.5}


def test_hash_follows_lighting_and_ignores_absent_key():
    spec = parse_spec(SCENE)
    d = spec_to_dict(spec)
    assert d["view_sets"][1]["lights"] == {"bulb": 0.0, "panel": 1.5, "sky": 0.5}
    assert "lights" not in d["view_sets"][3]  # absent: specs without it keep their hashes
    other = parse_spec(SCENE.replace("lights: {bulb: 2}", "lights: {bulb: 3}"))
    assert spec_sha256(other) != spec_sha256(spec)
    same = parse_spec(SCENE.replace("lights: [bulb, sky]", "lights: {bulb: 1, sky: 1}"))
    assert spec_sha256(same) == spec_sha256(spec)  # list and mapping forms resolve alike


def test_variant_keeps_view_set_lighting():
    from scenegen.spec.variants import derive_variant

    text = SCENE + ("variation:\n  seed: 3\n  lights: {bulb: {intensity_scale: [0.5, 2]}}\n"
                    "  views: {translation_m: 0.05, rotation_deg: 2}\n")
    spec = parse_spec(text)
    var = derive_variant(spec, 1)  # view jitter rewrites every view set as a pose list
    assert [vs.lights for vs in var.view_sets] == [vs.lights for vs in spec.view_sets]
    assert [v.light_scales for v in resolve_views(var)] == [v.light_scales for v in resolve_views(spec)]


# --- rendering --------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def built():
    from scenegen.render.backend import load_mitsuba

    load_mitsuba("llvm_ad_rgb")
    from scenegen.render.scene import build_scene

    spec = parse_spec(SCENE)
    return spec, resolve_views(spec), build_scene(spec, spp=16, sampler="ldsampler", max_depth=3)


def _render(built, scales, seed=7):
    from scenegen.render.frames import render_view

    spec, views, b = built
    return render_view(b.device, "cam", views[0].cam_from_world, spp=16, seed=seed, light_scales=scales)


@pytest.mark.render
def test_emitter_power_keys_cover_every_light_type(built):  # built: Mitsuba loaded first
    from scenegen.render.lights import EMITTER_POWER_PARAM
    from scenegen.spec import model as m

    assert set(EMITTER_POWER_PARAM) == {m.AreaLight, m.PointLight, m.SpotLight, m.ConstantLight, m.EnvmapLight,
                                        m.DirectionalLight}


@pytest.mark.render
def test_power_of_two_scale_is_exact(built):
    one = _render(built, (1.0, 0.0, 0.0))
    two = _render(built, (2.0, 0.0, 0.0))
    assert one.max() > 0.1  # the point light lights the scene
    np.testing.assert_allclose(two, 2.0 * one, rtol=0, atol=TOL_POWER_OF_TWO_SCALE)


@pytest.mark.render
def test_spot_and_envmap_scale(built, tmp_path):
    """The other two light types' power parameters (spot intensity, envmap scale)."""
    from scenegen.dataset import codecs as sio
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    env = np.full((16, 32, 3), 0.2, np.float32)
    env[:8] = (0.1, 0.2, 0.6)
    sio.write_exr(tmp_path / "env.exr", sio.pack_channels("", env, ("R", "G", "B")))
    spec = parse_spec("""
objects:
  - {name: floor, shape: {type: plane, size: [4, 4]}, material: {type: diffuse, color: 0.5}}
lights:
  - {type: spot, position: [0.5, -0.5, 2], target: [0, 0, 0], intensity: 5, cutoff_deg: 25}
  - {type: envmap, path: env.exr, scale: 0.5}
cameras:
  cam: {size: [48, 36], fov_deg: 60}
views:
  - camera: cam
    look_at: [{eye: [0, -2, 1.5], target: [0, 0, 0]}]
""", file=str(tmp_path / "s.yaml"), base_dir=tmp_path)
    b = build_scene(spec, spp=8, sampler="ldsampler", max_depth=2)
    pose = resolve_views(spec)[0].cam_from_world
    r = lambda k: render_view(b.device, "cam", pose, spp=8, seed=1, light_scales=k)
    for one, two in (((1.0, 0.0), (2.0, 0.0)), ((0.0, 1.0), (0.0, 2.0))):
        a = r(one)
        assert a.max() > 0.05, one
        np.testing.assert_allclose(r(two), 2.0 * a, rtol=0, atol=TOL_POWER_OF_TWO_SCALE)
    assert not r((0.0, 0.0)).any()


@pytest.mark.render
def test_only_light_at_zero_is_black(built):
    assert not _render(built, (0.0, 0.0, 0.0)).any()
    dark = _render(built, (0.0, 0.0, 0.0), seed=8)
    assert np.array_equal(dark, np.zeros_like(dark))


@pytest.mark.render
def test_lights_superpose(built):
    """With the same lights on (same samples), the image is linear in each light's power:
    image(k) + image(k') = image(k + k')."""
    k, k2 = (0.3, 1.7, 0.45), (1.0, 0.5, 2.0)
    a, b = _render(built, k), _render(built, k2)
    both = _render(built, tuple(x + y for x, y in zip(k, k2)))
    expected = a.astype(np.float64) + b
    floor = 1e-6 * expected.max()
    rel = np.abs(both - expected) / np.maximum(expected, floor)
    print(f"superposition: max relative error {rel.max():.2e}")
    assert rel.max() < TOL_SUPERPOSITION_REL


@pytest.mark.render
def test_light_off_is_as_if_absent(tmp_path):
    """A point or constant light at 0 has no geometry and takes no light samples: the image is
    bit for bit that of the spec without it."""
    from scenegen.render.backend import load_mitsuba

    load_mitsuba("llvm_ad_rgb")
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    lights = ["  - {type: point, name: bulb, position: [1, -1, 2], intensity: 3}\n",
              "  - {type: point, name: extra, position: [-1, -1, 2], intensity: 3}\n",
              "  - {type: constant, name: sky, radiance: 0.2}\n"]
    base = ("objects:\n  - {name: floor, shape: {type: plane, size: [4, 4]}, material: {type: diffuse, color: 0.5}}\n"
            "  - {name: ball, shape: {type: sphere, radius: 0.4}, transform: {translation: [0, 0, 0.4]}}\n"
            "cameras:\n  cam: {size: [64, 48], fov_deg: 50}\n"
            "views:\n  - camera: cam\n    look_at: [{eye: [0, -3, 2], target: [0, 0, 0.3]}]\nlights:\n")
    spec = parse_spec(base + "".join(lights))
    pose = resolve_views(spec)[0].cam_from_world
    b = build_scene(spec, spp=16, sampler="ldsampler", max_depth=3)
    for on in (0, 2):  # only the bulb; only the sky
        alone = parse_spec(base + lights[on])
        expected = render_view(build_scene(alone, spp=16, sampler="ldsampler", max_depth=3).device, "cam", pose,
                               spp=16, seed=1)
        got = render_view(b.device, "cam", pose, spp=16, seed=1, light_scales=tuple(float(i == on) for i in range(3)))
        assert expected.max() > 0.01 and np.array_equal(got, expected), on


@pytest.mark.render
def test_state_restored_whatever_came_before(built):
    """Every render sets the lighting it needs: None after other lightings is the loaded scene."""
    from scenegen.render.frames import render_view
    from scenegen.render.scene import build_scene

    spec, views, b = built
    fresh = build_scene(spec, spp=16, sampler="ldsampler", max_depth=3)
    a = render_view(fresh.device, "cam", views[0].cam_from_world, spp=16, seed=3)
    _render(built, (0.0, 2.0, 0.25))
    _render(built, (2.0, 0.0, 0.0))
    again = render_view(b.device, "cam", views[0].cam_from_world, spp=16, seed=3)
    assert b.light_scales == (1.0, 1.0, 1.0)
    assert np.array_equal(a, again)


# --- through the pipeline: truth, cameras.json, order independence ---------------------------
@pytest.fixture(scope="module")
def spec_file(tmp_path_factory):
    p = tmp_path_factory.mktemp("lit") / "lit.yaml"
    p.write_text(SCENE)
    return p


@pytest.fixture(scope="module")
def dataset(spec_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("lit_run") / "a"
    assert main(["render", str(spec_file), "-o", str(out), "-q"]) == 0
    return out


@pytest.mark.render
def test_cameras_json_records_view_set_and_lights(dataset):
    views = json.loads((dataset / "cameras.json").read_text())["views"]
    got = {name: (e["view_set"], e["lights"]) for name, e in views.items()}
    assert got == {
        "ref_0000": ("ref", {"bulb": 1.0, "panel": 0.0, "sky": 1.0}),
        "light_0001": ("light", {"bulb": 0.0, "panel": 1.5, "sky": 0.5}),
        "light_0002": ("light", {"bulb": 2.0, "panel": 0.0, "sky": 0.0}),
        "all_0003": ("all", {"bulb": 1.0, "panel": 1.0, "sky": 1.0}),
    }


@pytest.mark.render
def test_truth_identical_and_images_differ_across_lightings(dataset):
    d = Dataset(dataset)
    names = d.views
    for name in names[1:]:  # same pose, other lights: the truth files are the same bytes
        for kind in ("truth", "ids", "valid"):
            a = (dataset / f"truth/{names[0]}{'' if kind == 'truth' else '_' + kind}"
                 f"{'.png' if kind == 'valid' else '.exr'}").read_bytes()
            b = (dataset / f"truth/{name}{'' if kind == 'truth' else '_' + kind}"
                 f"{'.png' if kind == 'valid' else '.exr'}").read_bytes()
            assert a == b, (name, kind)
    lin = [d.linear_image(v) for v in names]
    for i in range(len(lin)):
        for j in range(i + 1, len(lin)):
            assert np.abs(lin[i] - lin[j]).mean() > 1e-3, (names[i], names[j])


@pytest.mark.render
def test_view_order_does_not_matter(spec_file, dataset, tmp_path):
    """Render the last views first (fresh scene), then resume the rest: the same bytes."""
    out = tmp_path / "b"
    assert main(["render", str(spec_file), "-o", str(out), "--frames", "2-3", "-q"]) == 0
    assert main(["render", str(spec_file), "-o", str(out), "--resume", "-q"]) == 0
    for p in sorted(dataset.rglob("*")):
        if p.is_file():
            assert p.read_bytes() == (out / p.relative_to(dataset)).read_bytes(), p.relative_to(dataset)


STEREO = """
name: lit_stereo
render: {spp: 4, max_depth: 2, sampler: ldsampler}
objects:
  - {name: floor, shape: {type: plane, size: [4, 4]}, material: {type: diffuse, color: 0.5}}
lights:
  - {type: point, name: bulb, position: [0, 0, 2], intensity: 4}
cameras:
  cam: {size: [64, 48], fov_deg: 60}
rigs:
  st: {type: stereo, left: cam, right: cam, baseline_m: 0.1}
views:
  - rig: st
    lights: {bulb: 0}
    look_at: [{eye: [0, -2, 1.5], target: [0, 0, 0]}]
  - camera: cam
    look_at: [{eye: [0, -2, 1.5], target: [0, 0, 0]}]
crossview: {pairs: none, flow: false, stereo: true, targets: false}
"""


@pytest.mark.render
def test_rectified_stereo_uses_the_left_views_lighting(tmp_path):
    """The lit view renders last, yet the rig's rectified pair is rendered with its lights off."""
    from scenegen.dataset import codecs as sio

    p = tmp_path / "s.yaml"
    p.write_text(STEREO)
    out = tmp_path / "out"
    assert main(["render", str(p), "-o", str(out), "-q"]) == 0
    d = Dataset(out)
    assert d.linear_image("cam_0001").max() > 0.05 and not d.linear_image("st_left_0000").any()
    for side in ("left", "right"):
        lin = sio.unpack_channels(sio.read_exr(out / f"crossview/stereo/st_left_0000/{side}_linear.exr"),
                                  "", ("R", "G", "B"))
        assert not lin.any(), side
