"""to_yaml is the parser's inverse: every bundled scene and a spec using every section and kind
round-trips (same resolved spec, same hash); a spec built in Python is validated by the YAML's
parser with errors naming the field (scenegen.api)."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from scenegen.api import (
    DiffuseMaterial, Orbit, PointLight, Scene, SceneObject, SpecError, Sphere, ViewSet, camera, obj,
)
from scenegen.dataset.codecs import write_png
from scenegen.spec import check_spec, load_spec, parse_spec, same_spec, spec_sha256, spec_to_dict, to_yaml

ROOT = Path(__file__).resolve().parents[3]
BUNDLED = sorted([*ROOT.glob("scenes/*.yaml"), *ROOT.glob("scenes/examples/*.yaml")])

EVERYTHING = """
name: everything
description: every section and kind the parser knows
seed: 7
render: {spp: 5, max_depth: -1, seed: 3, sampler: multijitter, bit_depth: 16, motion_subframes: 4}
materials:
  img: {type: diffuse, texture: {type: image, path: tex.png}}
  speck: {type: plastic, texture: {type: speckle, params: {density: 0.4}}, roughness: 0.2, ior: 1.6}
  metal: {type: conductor, material: Cu, roughness: 0.05}
objects:
  - {name: floor, shape: {type: plane, size: [4, 3]}, material: img}
  - {name: box, shape: {type: box, size: [0.2, 0.3, 0.4]}, material: speck,
     transform: {translation: [0.1, 0.2, 0.2], rotation_deg: [10, 20, 33], order: ZYX, scale: 1.5}}
  - {name: cyl, shape: {type: cylinder, radius: 0.1, height: 0.3}, material: metal,
     transform: {rotation_quat_wxyz: [0.9, 0.1, 0.2, 0.3], scale: [1, 2, 3]}, instance_id: 9}
  - {name: tor, shape: {type: torus, major_radius: 0.3, minor_radius: 0.05}, material: {type: diffuse, color: 0.3},
     motion: {linear_velocity_mps: [0.1, 0, 0], angular_velocity_deg_s: [0, 0, 5]}}
  - {name: blob, shape: {type: blob, radius: 0.2, amplitude: 0.1, frequency: 3, subdivisions: 3}}
  - {name: mesh, mesh: tri.ply, transform: {translation: [1, 1, 0]}}
  - {name: cb, target: {type: checkerboard, inner_cols: 5, inner_rows: 4, square_m: 0.04}}
  - {name: ch, target: {type: charuco, squares_x: 5, squares_y: 4, square_m: 0.04, marker_m: 0.03, dictionary: DICT_5X5_100,
     legacy_pattern: true}, transform: {translation: [0.5, 0, 0]}}
  - {name: ag, target: {type: aruco_grid, markers_x: 3, markers_y: 2, marker_m: 0.04, separation_m: 0.01,
     dictionary: DICT_4X4_50, first_id: 3}, transform: {translation: [-0.5, 0, 0]}}
lights:
  - {type: point, position: [0, -2, 3], intensity: [5, 6, 7]}
  - {type: spot, name: spot, position: [1, -1, 2], target: [0, 0, 0], intensity: 4, cutoff_deg: 30}
  - {type: area, name: a1, size: [0.5, 0.5], position: [0, -1, 2], look_at: [0, 0, 0], radiance: 3}
  - {type: area, name: a2, transform: {translation: [0, 0, 3], rotation_deg: [180, 0, 0]}, radiance: [1, 2, 3]}
  - {type: constant, radiance: 0.1}
  - {type: envmap, name: env, path: tex.png, scale: 0.5, rotation_z_deg: 30}
cameras:
  pin: {size: [64, 48], fov_deg: 60}
  cv: {model: opencv, size: [64, 48], fx: 50, fy: 51, cx: 31, cy: 24, skew: 0.1, dist: [-0.05, 0.01, 0.001, 0.0005, 0.001],
       lens: {f_number: 2.8, focus_distance_m: 2, pixel_pitch_um: 3}, shutter: {exposure_s: 0.01, rolling_readout_s: 0.02},
       chromatic_aberration: {red_focal_scale: 1.001, blue_focal_scale: 0.999}}
  fish: {model: fisheye, size: [64, 48], fx: 20, dist: [0.01, 0, 0, 0]}
  noisy: {size: [64, 48], fx: 60, imaging: {preset: smartphone, sensor: {dark_noise_e: 3}, white_balance: [2, 1, 1.5]}}
  raw: {size: [64, 48], fx: 60, imaging: {bayer: RGGB, raw: {dng: true, png: true}, white_balance: auto, bit_depth: 16}}
rigs:
  st: {type: stereo, left: cv, right: pin, baseline_m: 0.1, vergence_deg: 3}
  m: {type: multi, members: [{camera: pin}, {camera: fish, name: f, rig_from_cam: {translation: [0.1, 0, 0], rotation_deg: [0, 10, 0]}}]}
views:
  - {camera: pin, orbit: {center: [0, 0, 0.2], radius_m: 2, elevations_deg: [20, 40], count: 2, start_azimuth_deg: 15}}
  - {name: la, camera: cv, look_at: [{eye: [1, -2, 1], target: [0, 0, 0]}, {eye: [-1, -2, 1], target: [0, 0, 0], up: [0, 0.1, 1]}],
     lights: [spot, a1]}
  - {camera: fish, poses: [{cam_from_world: {translation: [0, 0, 3], rotation_deg: [180, 0, 0]}},
     {world_from_cam: [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 3], [0, 0, 0, 1]]}], lights: {light0: 2, env: 0.5}}
  - {camera: noisy, random: {count: 2, eye_box: {min: [-1, -3, 1], max: [1, -2, 2]}, target: [0, 0, 0], min_distance_m: 0.5}}
  - {camera: raw, random: {count: 1, seed: 4, eye_box: {min: [-1, -3, 1], max: [1, -2, 2]},
     target_box: {min: [0, 0, 0], max: [0.1, 0.1, 0.1]}, up: [0, 0, 1]}}
  - {rig: st, path: {line: {from: [-1, -2, 1], to: [1, -2, 1]}, count: 2, target: [0, 0, 0]}, motion: {linear_velocity_mps: [0.2, 0, 0]}}
  - {rig: m, path: {circle: {center: [0, 0, 1], radius_m: 2, height_m: 0.5, start_azimuth_deg: 10}, count: 2}}
crossview:
  pairs: [[pin_0000, la_0004]]
  flow: false
  matches: {count: 50, sigma_px: 0.3, near_miss_px: [2, 5]}
  sift: true
  sift_ratio: 0.7
variation:
  objects:
    box: {position: {min: [0, 0, 0], max: [0.1, 0.1, 0]}, yaw_deg: [-5, 5]}
    tor: {color: {min: [0.1, 0.1, 0.1], max: [0.5, 0.5, 0.5]}}
    blob: {reseed: true}
  lights: {light0: {intensity_scale: [0.5, 2], position_jitter_m: 0.1}}
  cameras: {cv: {focal_scale: [0.98, 1.02], principal_point_px: 1, dist_jitter: [0.01, 0, 0, 0, 0]}}
  views: {translation_m: 0.01, rotation_deg: 0.5}
"""


@pytest.fixture(scope="module")
def everything(tmp_path_factory):
    import trimesh

    d = tmp_path_factory.mktemp("everything")
    write_png(d / "tex.png", np.arange(48, dtype=np.uint8).reshape(4, 4, 3))
    trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]]).export(d / "tri.ply")
    (d / "everything.yaml").write_text(EVERYTHING)
    return load_spec(d / "everything.yaml")


def _round_trip(spec):
    back = parse_spec(to_yaml(spec), file="<round trip>", base_dir=spec.base_dir)
    assert spec_to_dict(back) == spec_to_dict(spec)  # exact floats, every field
    assert same_spec(back, spec) and spec_sha256(back) == spec_sha256(spec)
    assert parse_spec(to_yaml(back), base_dir=spec.base_dir) is not None and to_yaml(back) == to_yaml(spec)
    return back


@pytest.mark.parametrize("path", BUNDLED, ids=[p.name for p in BUNDLED])
def test_every_bundled_scene_round_trips(path):
    _round_trip(load_spec(path))


def test_every_section_and_kind_round_trips(everything):
    kinds = {type(o.geometry).__name__ for o in everything.objects} | {li.type for li in everything.lights}
    assert kinds >= {"Plane", "Box", "Cylinder", "Torus", "Blob", "Mesh", "CheckerboardTarget", "CharucoTarget",
                     "ArucoGridTarget", "point", "spot", "area", "constant", "envmap"}
    assert {type(vs.placement).__name__ for vs in everything.view_sets} == {
        "Orbit", "LookAtList", "PoseList", "RandomPoses", "LinePath", "CirclePath"}
    _round_trip(everything)


def test_a_spec_built_in_python_is_the_yaml_spec():
    spec = Scene("ball", objects=[obj("ball", Sphere(radius=0.3), material=DiffuseMaterial(color=(0.8, 0.2, 0.1)),
                                      translation=(0, 0, 0.3), rotation_deg=(0, 0, 45))],
                 lights=[PointLight(name="sun", position=(0, -2, 3), intensity=(20, 20, 20))],
                 cameras=[camera("cam", size=(64, 48), fov_deg=60)],
                 views=[ViewSet(name=None, camera="cam", rig=None, placement=Orbit(radius_m=2, count=2))])
    text = """
name: ball
objects:
  - {name: ball, shape: {type: sphere, radius: 0.3}, material: {type: diffuse, color: [0.8, 0.2, 0.1]},
     transform: {translation: [0, 0, 0.3], rotation_deg: [0, 0, 45]}}
lights: [{type: point, name: sun, position: [0, -2, 3], intensity: 20}]
cameras: {cam: {size: [64, 48], fov_deg: 60}}
views: [{camera: cam, orbit: {radius_m: 2, count: 2}}]
"""
    assert spec_sha256(spec) == spec_sha256(parse_spec(text))
    _round_trip(spec)


@pytest.mark.parametrize("build, message", [
    (lambda: Scene(objects=[obj("ball", Sphere(radius=-0.3))]),
     "<python>: objects[0].shape.radius: expected a value > 0 (metres), got -0.3"),
    (lambda: Scene(cameras=[camera("cam", size=(64, 48), fx=-3)]),
     "<python>: cameras.cam.fx: expected a value > 0 (pixels), got -3"),
    (lambda: Scene(objects=[obj("ball", Sphere(radius=0.3), material="nope")]),
     "<python>: objects[0].material: undefined material 'nope'"),
    (lambda: Scene(cameras=[camera("cam", size=(64, 48), fx=50)],
                   views=[ViewSet(name=None, camera="nocam", rig=None, placement=Orbit(radius_m=2, count=2))]),
     "<python>: views[0].camera: undefined camera 'nocam'"),
    (lambda: Scene(objects=[obj("a", Sphere()), obj("a", Sphere())]), "<python>: objects[1].name: duplicate object name 'a'"),
])
def test_python_errors_name_the_field(build, message):
    with pytest.raises(SpecError) as e:
        build()
    assert str(e.value).startswith(message), str(e.value)


def test_inconsistent_values_are_named():
    spec = Scene(objects=[obj("ball", Sphere(radius=0.3))])
    bad = dataclasses.replace(spec, objects=(dataclasses.replace(spec.objects[0], object_id=5),))
    assert isinstance(bad.objects[0], SceneObject)
    with pytest.raises(SpecError, match=r"objects\[0\]\.object_id: 5, but the spec's rules give 1"):
        check_spec(bad)


def test_matrix_transform_is_exact_and_exclusive():
    base = "objects:\n  - {name: b, shape: sphere, transform: %s}\n"
    R = [[0.36, 0.48, -0.8, 1.5], [-0.8, 0.6, 0.0, 0.25], [0.48, 0.64, 0.6, -3.0], [0, 0, 0, 1]]
    spec = parse_spec(base % f"{{matrix: {R}}}")
    assert spec.objects[0].transform.world_from_object.matrix.tolist() == R
    with pytest.raises(SpecError, match=r"objects\[0\]\.transform\.translation: give either 'matrix' or 'translation'"):
        parse_spec(base % f"{{matrix: {R}, translation: [0, 0, 0]}}")
    with pytest.raises(SpecError, match="expected a rigid transform"):
        parse_spec(base % "{matrix: [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]}")


SURFACES = """
name: surfaces
materials:
  glass: {type: dielectric, ior: 1.5, roughness: 0.05, transmittance: [1, 0.9, 0.9]}
  pane: {type: thin_dielectric, ior: 1.33}
  pbr: {type: principled, texture: {type: image, path: tex.png}, metallic: 0.3, roughness: 0.4, specular: 0.6,
        spec_trans: 0.1, clearcoat: 0.2, sheen: 0.1, normal_map: tex.png, bump_map: {type: image, path: tex.png},
        bump_scale: 0.002}
  holes: {type: diffuse, color: 0.4, alpha: tex.png, alpha_cutoff: 0.3, alpha_blend: true}
objects:
  - {name: a, shape: {type: sphere, radius: 0.2}, material: glass}
  - {name: b, shape: {type: plane, size: [1, 1]}, material: pane}
  - {name: c, shape: {type: box, size: [0.2, 0.2, 0.2]}, material: pbr}
  - {name: d, shape: {type: plane, size: [1, 1]}, material: holes, transform: {translation: [0, 0, -0.1]}}
  - {name: own, mesh: quad.obj}
  - {name: replaced, mesh: quad.obj, material: {type: plastic, color: 0.5}}
cameras:
  wide: {model: opencv, size: [64, 48], fx: 30, fy: 30, cx: 32, cy: 24, dist: [-0.4, 0.03, 0, 0, 0], mask_beyond_fold: true}
views: [{camera: wide, orbit: {radius_m: 2, count: 1}}]
"""


def test_surface_materials_own_mesh_materials_and_the_fold_opt_in_round_trip(tmp_path):
    write_png(tmp_path / "tex.png", np.arange(48, dtype=np.uint8).reshape(4, 4, 3))
    (tmp_path / "quad.mtl").write_text("newmtl red\nKd 0.8 0.1 0.1\n")
    (tmp_path / "quad.obj").write_text("mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl red\nf 1 2 3\nf 1 3 4\n")
    (tmp_path / "s.yaml").write_text(SURFACES)
    spec = load_spec(tmp_path / "s.yaml")
    by_name = {o.name: o for o in spec.objects}
    assert by_name["own"].geometry.own_materials and not by_name["replaced"].geometry.own_materials
    assert spec.cameras["wide"].mask_beyond_fold
    assert {type(o.material).__name__ for o in spec.objects} >= {
        "DielectricMaterial", "ThinDielectricMaterial", "PrincipledMaterial"}
    back = _round_trip(spec)
    assert {o.name: o.geometry.own_materials for o in back.objects if o.name in ("own", "replaced")} == {
        "own": True, "replaced": False}
    assert "mask_beyond_fold: true" in to_yaml(spec)
