"""Spec defaults, units and ranges are stated once, on the dataclass fields: every field with a
default carries unit metadata, the parsers take every default from the dataclasses (a restated
literal cannot pass the patch test below), and the camera enumerations are the registry's."""
from __future__ import annotations

import ast
import dataclasses
import sys
from dataclasses import MISSING
from pathlib import Path
from types import MappingProxyType

import pytest

from scenegen.errors import SpecError
from scenegen.geometry import optics
from scenegen.geometry.camera import MODEL_NAMES, MODELS
from scenegen.geometry.color import BIT_DEPTHS
from scenegen.imaging import ExposureParams, ImagingParams, RawOutput, SensorParams
from scenegen.imaging.vignetting import VignettingParams
from scenegen.located_yaml import Document
from scenegen.spec import model as m
from scenegen.spec import parse_spec, reference
from scenegen.spec.model.meta import META_KEY, NOT_GIVEN, field_info, spec_fields
from scenegen.spec.parse.read import read_float
from scenegen.spec.sensors import SENSOR_KINDS
from scenegen.spec.sensors.imu import ImuSpec
from scenegen.spec.sensors.lidar import LidarSpec
from scenegen.spec.sensors.wheel_odometry import WheelOdometrySpec
from scenegen.spec.sensors.tof import TofSpec
from scenegen.spec.sensors.projector import ProjectorSpec

sys.path.insert(0, str(Path(__file__).parent))
from clock_sensor import CLOCK  # noqa: E402  (a test-only sensor kind: a second kind to switch to)

ROOT = Path(__file__).resolve().parents[3]
PARSE_DIR = ROOT / "scenegen" / "spec" / "parse"
CAM = "cameras:\n  cam: {size: [64, 48], fx: 50}\n"
VIEW = "    look_at: [{eye: [0, -2, 1], target: [0, 0, 0]}]\n"
UP = (0.0, 0.1, 1.0)


def model_classes():
    return sorted((obj for obj in vars(m).values()
                   if isinstance(obj, type) and dataclasses.is_dataclass(obj)
                   and obj.__module__ != "scenegen.spec.model.meta"),  # not Meta, FieldInfo
                  key=lambda c: c.__name__)


@pytest.mark.parametrize("cls", model_classes(), ids=lambda c: c.__name__)
def test_every_field_with_a_default_has_unit_metadata(cls):
    for f in dataclasses.fields(cls):
        has_default = f.default is not MISSING or f.default_factory is not MISSING
        if not has_default or not f.init or f.name == "where":  # discriminators, locations
            continue
        meta = f.metadata.get(META_KEY)
        assert meta is not None, f"{cls.__name__}.{f.name} has a default but no param()/part()"
        assert meta.unit.strip(), f"{cls.__name__}.{f.name}: empty unit"


def test_every_value_field_is_in_the_reference_table():
    missing = reference.all_spec_classes() - reference.covered_classes()
    assert not missing, sorted(c.__name__ for c in missing)


# (record, field, spec text, the parsed value, another valid default)
S = lambda i: (lambda s: s.objects[0].geometry)  # noqa: E731
SEQ = "sequence: {fps: 10, frames: 3}\n"
JOINT = ("objects:\n  - {name: a, shape: box}\n  - {name: b, shape: box, parent: a, joint: {type: "
         "revolute, axis: [0, 0, 1], keyframes: [{time_s: 0, angle_deg: 0}]}}\n")
#: A drop with its poses recorded: parsed without the engine.
DROP = ("objects:\n  - {name: t, shape: box}\n  - {name: s, shape: sphere}\n"
        "placement: {type: drop, onto: t, objects: [s], poses: {s: {translation: [0, 0, 1]}}}\n")
CASES = [
    *[(m.RenderSettings, k, "render: {}\n", lambda s, k=k: getattr(s.render, k), v)
      for k, v in (("spp", 16), ("max_depth", 3), ("seed", 5), ("variant", "scalar_rgb"),
                   ("bit_depth", 16), ("sampler", "independent"), ("motion_subframes", 4), ("exr_compression", "none"))],
    (m.SceneSpec, "description", "name: t\n", lambda s: s.description, "other"),
    (m.SceneSpec, "seed", "name: t\n", lambda s: s.seed, 3),
    (m.DiffuseMaterial, "color", "materials:\n  a: {type: diffuse}\n",
     lambda s: s.materials["a"].color, (0.25, 0.25, 0.25)),
    *[(m.PlasticMaterial, k, "materials:\n  a: {type: plastic}\n",
       lambda s, k=k: getattr(s.materials["a"], k), v)
      for k, v in (("color", (0.25, 0.25, 0.25)), ("roughness", 0.3), ("ior", 1.6))],
    *[(m.ConductorMaterial, k, "materials:\n  a: {type: conductor}\n",
       lambda s, k=k: getattr(s.materials["a"], k), v)
      for k, v in (("material", "Cu"), ("roughness", 0.3))],
    *[(m.DielectricMaterial, k, "materials:\n  a: {type: dielectric}\n",
       lambda s, k=k: getattr(s.materials["a"], k), v)
      for k, v in (("ior", 1.333), ("roughness", 0.2), ("transmittance", (0.9, 0.9, 0.9)))],
    *[(m.ThinDielectricMaterial, k, "materials:\n  a: {type: thin_dielectric}\n",
       lambda s, k=k: getattr(s.materials["a"], k), v)
      for k, v in (("ior", 1.333), ("transmittance", (0.9, 0.9, 0.9)))],
    *[(m.PrincipledMaterial, k, "materials:\n  a: {type: principled}\n",
       lambda s, k=k: getattr(s.materials["a"], k), v)
      for k, v in (("color", (0.25, 0.25, 0.25)), ("metallic", 0.5), ("roughness", 0.2),
                   ("specular", 0.3), ("spec_trans", 0.4), ("clearcoat", 0.6), ("sheen", 0.7))],
    *[(m.SurfaceMaps, k, "materials:\n  a: {type: diffuse, alpha: env.png, bump_map: env.png}\n",
       lambda s, k=k: getattr(s.materials["a"].maps, k), v)
      for k, v in (("bump_scale", 0.5), ("alpha_cutoff", 0.3), ("alpha_blend", True))],
    *[(cls, k, f"objects:\n  - {{name: o, shape: {{type: {kind}}}}}\n",
       lambda s, k=k: getattr(s.objects[0].geometry, k), v)
      for cls, kind, k, v in (
          (m.Plane, "plane", "size", (2.0, 3.0)), (m.Box, "box", "size", (2.0, 3.0, 4.0)),
          (m.Sphere, "sphere", "radius", 0.7), (m.Cylinder, "cylinder", "radius", 0.7),
          (m.Cylinder, "cylinder", "height", 2.0), (m.Torus, "torus", "major_radius", 0.9),
          (m.Torus, "torus", "minor_radius", 0.3), (m.Blob, "blob", "radius", 0.7),
          (m.Blob, "blob", "amplitude", 0.2), (m.Blob, "blob", "frequency", 3.0),
          (m.Blob, "blob", "subdivisions", 2))],
    (m.ArucoGridTarget, "first_id",
     "objects:\n  - name: o\n    target: {type: aruco_grid, markers_x: 2, markers_y: 2, "
     "marker_m: 0.05, separation_m: 0.01, dictionary: DICT_4X4_50}\n",
     lambda s: s.objects[0].geometry.first_id, 3),
    (m.CharucoTarget, "legacy_pattern",
     "objects:\n  - name: o\n    target: {type: charuco, squares_x: 5, squares_y: 4, "
     "square_m: 0.04, marker_m: 0.032, dictionary: DICT_4X4_50}\n",
     lambda s: s.objects[0].geometry.legacy_pattern, True),
    (m.Mesh, "scale", "objects:\n  - {name: o, mesh: {path: mesh.stl}}\n",
     lambda s: s.objects[0].geometry.scale, 0.01),
    (m.Transform, "scale", "objects:\n  - {name: o, shape: sphere, transform: {}}\n",
     lambda s: s.objects[0].transform.scale, (2.0, 2.0, 2.0)),
    (m.AreaLight, "size", "lights:\n  - {type: area, position: [0, 0, 2], look_at: [0, 0, 0], "
     "radiance: 1}\n", lambda s: s.lights[0].size, (2.0, 0.5)),
    (m.SpotLight, "cutoff_deg", "lights:\n  - {type: spot, position: [0, 0, 2], "
     "target: [0, 0, 0], intensity: 1}\n", lambda s: s.lights[0].cutoff_deg, 30.0),
    *[(m.EnvmapLight, k, "lights:\n  - {type: envmap, path: env.png}\n",
       lambda s, k=k: getattr(s.lights[0], k), v)
      for k, v in (("scale", 2.0), ("rotation_z_deg", 45.0))],
    *[(m.CameraSpec, k, CAM, lambda s, k=k: getattr(s.cameras["cam"], k), v)
      for k, v in (("model", "opencv"), ("skew", 1.0), ("fov_deg", 60.0), ("mask_beyond_fold", True))],
    *[(optics.Shutter, k, CAM.replace("fx: 50", "fx: 50, shutter: {}"),
       lambda s, k=k: getattr(s.cameras["cam"].optics.shutter, k), v)
      for k, v in (("exposure_s", 0.01), ("rolling_readout_s", 0.001))],
    *[(optics.ChromaticAberration, k, CAM.replace("fx: 50", "fx: 50, chromatic_aberration: {}"),
       lambda s, k=k: getattr(s.cameras["cam"].optics.chromatic_aberration, k), v)
      for k, v in (("red_focal_scale", 1.1), ("blue_focal_scale", 0.9))],
    *[(optics.Motion, k, CAM + "views:\n  - camera: cam\n    motion: {}\n" + VIEW,
       lambda s, k=k: getattr(s.view_sets[0].motion, k), v)
      for k, v in (("linear_velocity_mps", (1.0, 0.0, 0.0)),
                   ("angular_velocity_deg_s", (0.0, 0.0, 10.0)))],
    *[(RawOutput, k, CAM.replace("fx: 50", f"fx: 50, imaging: {{bayer: RGGB, raw: {{{given}: true}}}}"),
       lambda s, k=k: getattr(s.cameras["cam"].imaging.raw, k), v)
      for k, given, v in (("dng", "png", False), ("png", "dng", True))],
    (m.Rig, "vergence_deg", CAM + "rigs:\n  st: {type: stereo, left: cam, right: cam, "
     "baseline_m: 0.1}\n", lambda s: s.rigs["st"].vergence_deg, 4.0),
    *[(m.Orbit, k, CAM + "views:\n  - camera: cam\n    orbit: {radius_m: 2, count: 2}\n",
       lambda s, k=k: getattr(s.view_sets[0].placement, k), v)
      for k, v in (("center", (0.0, 0.0, 0.5)), ("elevations_deg", (10.0,)),
                   ("start_azimuth_deg", 15.0))],
    (m.LookAt, "up", CAM + "views:\n  - camera: cam\n" + VIEW,
     lambda s: s.view_sets[0].placement.entries[0].up, UP),
    *[(m.RandomPoses, k, CAM + "views:\n  - camera: cam\n    random: {count: 2, eye_box: "
       "{min: [1, 1, 1], max: [2, 2, 2]}, target: [0, 0, 0]}\n",
       lambda s, k=k: getattr(s.view_sets[0].placement, k), v)
      for k, v in (("up", UP), ("min_distance_m", 0.1))],
    (m.LinePath, "up", CAM + "views:\n  - camera: cam\n    path: {line: {from: [0, -2, 1], "
     "to: [1, -2, 1]}, count: 2, target: [0, 0, 0]}\n", lambda s: s.view_sets[0].placement.up,
     UP),
    *[(m.CirclePath, k, CAM + "views:\n  - camera: cam\n    path: {circle: {radius_m: 2}, "
       "count: 3}\n", lambda s, k=k: getattr(s.view_sets[0].placement, k), v)
      for k, v in (("center", (0.0, 0.0, 0.2)), ("height_m", 0.5),
                   ("start_azimuth_deg", 10.0), ("up", UP))],
    *[(m.CrossviewSpec, k, CAM + "crossview: {}\n", lambda s, k=k: getattr(s.crossview, k), v)
      for k, v in (("pairs", "all"), ("flow", False), ("stereo", False), ("sift", True),
                   ("sift_ratio", 0.7), ("sift_inlier_px", 3.0), ("targets", False), ("ir_depth_range_m", (0.5, 4.0)))],
    *[(m.MatchSetSpec, k, CAM + "crossview: {matches: {}}\n",
       lambda s, k=k: getattr(s.crossview.matches, k), v)
      for k, v in (("count", 10), ("sigma_px", 1.0), ("outlier_fraction", 0.1),
                   ("near_miss_fraction", 0.3), ("near_miss_px", (1.0, 2.0)))],
    *[(m.TruthSpec, k, CAM + "truth: {}\n", lambda s, k=k: getattr(s.truth, k), v)
      for k, v in (("albedo", True), ("lights", True), ("defocus", True), ("boxes", True))],
    (m.TruthSpec, "objects", CAM + "objects:\n  - {name: b, shape: box, annotation: {}}\ntruth: {}\n",
     lambda s: s.truth.objects, True),
    (m.ObjectVariation, "reseed", "objects:\n  - {name: b, shape: blob}\n"
     "variation: {objects: {b: {}}}\n", lambda s: s.variation.objects[0].reseed, True),
    (m.LightVariation, "position_jitter_m", "lights:\n  - {type: point, name: p, "
     "position: [0, 0, 1], intensity: 1}\nvariation: {lights: {p: {}}}\n",
     lambda s: s.variation.lights[0].position_jitter_m, 0.1),
    *[(m.CameraVariation, k, CAM + "variation: {cameras: {cam: {}}}\n",
       lambda s, k=k: getattr(s.variation.cameras[0], k), v)
      for k, v in (("principal_point_px", 1.0), ("dist_jitter", (0.5,)))],
    *[(m.PoseJitter, k, "variation: {views: {}}\n", lambda s, k=k: getattr(s.variation.views, k),
       v) for k, v in (("translation_m", 0.01), ("rotation_deg", 1.0))],
    *[(m.SequenceSpec, k, SEQ, lambda s, k=k: getattr(s.sequence, k), v)
      for k, v in (("flow_steps", (2,)), ("start_s", 0.5))],
    *[(m.TrackSpec, k, SEQ.replace("frames: 3", "frames: 3, tracks: {}"),
       lambda s, k=k: getattr(s.sequence.tracks, k), v)
      for k, v in (("count", 10), ("query_frames", (1,)))],
    (m.TrajectorySpec, "interpolation", CAM + SEQ + "views:\n  - camera: cam\n    trajectory: "
     "{keyframes: [{time_s: 0, eye: [0, -2, 1], target: [0, 0, 0]}]}\n",
     lambda s: s.view_sets[0].placement.trajectory.interpolation, "linear"),
    *[(m.JointSpec, k, SEQ + JOINT, lambda s, k=k: getattr(s.objects[1].animation.joint, k), v)
      for k, v in (("origin", (0.1, 0.0, 0.0)), ("interpolation", "linear"))],
    *[(m.DropPlacement, k, DROP, lambda s, k=k: getattr(s.placement, k), v)
      for k, v in (("drop_height_m", 0.2), ("orientation", "yaw"), ("friction", 0.5), ("settle_s", 2.0),
                   ("rest_speed_m_s", 0.01))],
]
#: A camera and a clock of one name: a member naming it is either, as its kind says.
CLK = "cameras:\n  clk: {size: [64, 48], fx: 50}\nclocks:\n  clk: {}\nrigs:\n  r: {type: multi, members: [%s]}\n"
CASES += [
    (m.RigMember, "kind", CLK % "{sensor: clk}", lambda s: s.rigs["r"].members[0].kind, "clock"),
    (m.RigMember, "time_offset_s", CLK % "{kind: clock, sensor: clk}",
     lambda s: s.rigs["r"].members[0].time_offset_s, 0.25),
    (ImuSpec, "rate_hz", "imus:\n  imu0: {}\n", lambda s: s.sensors["imu"]["imu0"].rate_hz, 100.0),
]
CASES += [(LidarSpec, key, "lidars:\n  l0: {elevations_deg: [0]}\n",
           lambda s, key=key: getattr(s.sensors["lidar"]["l0"], key), other)
          for key, other in (("rows", 32), ("fov_h_deg", 90.0), ("fov_v_deg", 10.0), ("start_azimuth_deg", 5.0),
                             ("divergence_mrad", 1.0), ("footprint_rays", 3), ("return_mode", "last"),
                             ("range_noise_m", 0.1), ("reflectivity", 0.3), ("attenuation_per_m", 0.01),
                             ("min_intensity", 0.1), ("max_incidence_deg", 80.0), ("dropout_rate", 0.1))]
CASES += [(WheelOdometrySpec, key, "wheel_odometry:\n  w: {}\n",
           lambda s, key=key: getattr(s.sensors["wheel_odometry"]["w"], key), other)
          for key, other in [("rate_hz", 20.0), ("wheel_radius_m", 0.2), ("track_width_m", 0.3), ("slip_left", 0.1),
                             ("slip_right", 0.1), ("wheel_speed_noise_rad_s", 0.5)]]
TOF = "cameras:\n  ir: {size: [32, 24], fx: 30}\ntof_cameras:\n  t: {camera: ir}\n"
CASES += [(TofSpec, k, TOF, lambda s, k=k: getattr(s.sensors["tof"]["t"], k), v)
          for k, v in (("frequency_mhz", 20.0), ("spp", 4), ("max_bounces", 1), ("pixel_centre_rays", True),
                       ("integration_s", 0.002), ("signal_e_per_s_at_1m", 1e5), ("ambient_e_per_s", 10.0),
                       ("contrast", 0.5), ("noise", False), ("read_noise_e", 1.0), ("gain_dn_per_e", 0.5),
                       ("full_well_e", 1000.0), ("adc_bits", 12), ("min_amplitude_e", 5.0),
                       ("flying_threshold_m", 0.1))]
#: A projector of fixed defaults (its intrinsics required).
PROJ = "projectors:\n  p: {intrinsics: {size: [16, 8], fx: 20}%s}\n"
CASES += [(ProjectorSpec, k, PROJ % "", lambda s, k=k: getattr(s.sensors["projector"]["p"], k), v)
          for k, v in (("intensity_w_sr", (2.0, 2.0, 2.0)), ("gamma", 2.2), ("black_level", 0.05), ("falloff", "cos4"),
                       ("patterns", "binary"), ("pattern_axes", "rows"), ("pattern_inverse", False),
                       ("pattern_white_black", False), ("phase_steps", 8), ("stripe_px", 2), ("dots_density", 0.5),
                       ("dot_px", 2), ("linear_patterns", True))]
IDS = [f"{c[0].__name__}.{c[1]}" for c in CASES]


@pytest.fixture(autouse=True)
def clock_kind(monkeypatch):
    monkeypatch.setitem(SENSOR_KINDS, CLOCK.name, CLOCK)


def parse(text, tmp_path):
    (tmp_path / "env.png").write_bytes(b"not read at parse time")
    (tmp_path / "mesh.stl").write_bytes(b"solid not read at parse time")
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


@pytest.mark.parametrize("cls,name,text,get,other", CASES, ids=IDS)
def test_absent_key_gives_the_dataclass_default(tmp_path, cls, name, text, get, other):
    assert get(parse(text, tmp_path)) == field_info(cls, name).default


@pytest.mark.parametrize("cls,name,text,get,other", CASES, ids=IDS)
def test_parser_takes_the_default_from_the_dataclass(tmp_path, monkeypatch, cls, name, text,
                                                     get, other):
    """Change the default on the field (not in any parser): the parsed spec follows."""
    f = {f.name: f for f in dataclasses.fields(cls)}[name]
    meta = f.metadata.get(META_KEY)
    if meta is not None and meta.yaml_default is not NOT_GIVEN:
        new = dataclasses.replace(meta, yaml_default=other)
        monkeypatch.setattr(f, "metadata", MappingProxyType({**f.metadata, META_KEY: new}))
    else:
        monkeypatch.setattr(f, "default", other)
    assert field_info(cls, name).default == other
    assert get(parse(text, tmp_path)) == other


#: The imaging chain's records: an absent key keeps the value of the base record (a preset, or
#: the record's own constructor default), so no parser reads their defaults; checked below.
PRESET_BASED = {ImagingParams, ExposureParams, VignettingParams, SensorParams}


def test_the_patch_test_covers_every_fixed_default():
    """Every spec value with a fixed (not derived, not None) default is in CASES."""
    covered = {(c[0], c[1]) for c in CASES}
    fixed = {(cls, fi.name) for cls in reference.covered_classes() - PRESET_BASED
             for fi in spec_fields(cls)
             if not fi.meta.part and fi.default is not MISSING and fi.default is not None}
    assert fixed - covered == set(), sorted(f"{c.__name__}.{n}" for c, n in fixed - covered)


def test_an_imaging_block_without_a_preset_has_the_documented_defaults(tmp_path):
    """Without a preset every absent imaging value is its record's default as the reference
    table states it (field_info), but the derived bit depth and fixed-pattern seed."""
    cam = parse(CAM.replace("fx: 50", "fx: 50, imaging: {}"), tmp_path).cameras["cam"]
    for cls in PRESET_BASED:
        record = cam.imaging if cls is ImagingParams else getattr(
            cam.imaging, {ExposureParams: "exposure", VignettingParams: "vignetting",
                          SensorParams: "sensor"}[cls])
        for fi in spec_fields(cls):
            if not fi.meta.part and fi.default is not MISSING:
                assert getattr(record, fi.name) == fi.default, (cls.__name__, fi.name)


def test_a_reader_refuses_a_second_default():
    f = Document("spp: 3\n", "<t>", Path(".")).root.as_mapping()
    with pytest.raises(TypeError, match="must not give another"):
        read_float(f, m.RenderSettings, "spp", default=64)


def _literal(node) -> bool:
    """A constant other than None, or a tuple of constants not all None."""
    if isinstance(node, ast.Constant):
        return node.value is not None
    if isinstance(node, ast.Tuple):
        return all(isinstance(e, ast.Constant) for e in node.elts) and \
            any(e.value is not None for e in node.elts)
    return False


def _reads_key(node, key) -> bool:
    return any(isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)
               and n.func.attr == "get" and n.args and isinstance(n.args[0], ast.Constant)
               and n.args[0].value == key for n in ast.walk(node))


@pytest.mark.parametrize("path", sorted(PARSE_DIR.glob("*.py")), ids=lambda p: p.name)
def test_no_parser_states_a_literal_default(path):
    """``f.float(key, 0.5, ...)``, ``read_*(..., default=0.5)`` and ``... if "key" in f else
    'auto'`` would restate a dataclass default."""
    bad = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                and node.func.attr in ("float", "int", "vec3"):
            dflt = node.args[1:2] + [k.value for k in node.keywords if k.arg == "default"]
            if any(_literal(d) for d in dflt):
                bad.append(f"line {node.lineno}: .{node.func.attr}() with a literal default")
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id.startswith("read_"):
            if any(k.arg == "default" and _literal(k.value) for k in node.keywords):
                bad.append(f"line {node.lineno}: {node.func.id}(default=<literal>)")
        if isinstance(node, ast.IfExp) and isinstance(node.test, ast.Compare) \
                and isinstance(node.test.ops[0], ast.In) \
                and isinstance(node.test.left, ast.Constant) \
                and _reads_key(node.body, node.test.left.value) and _literal(node.orelse):
            bad.append(f"line {node.lineno}: '... if key in f else <literal>'")
    assert not bad, bad


# -- enumerations are the registries' --------------------------------------------------------
def camera(model_line: str, dist: str = "") -> str:
    return f"cameras:\n  c:\n    {model_line}\n    size: [64, 48]\n    fx: 50\n{dist}"


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_every_registered_camera_model_is_accepted(name):
    spec = parse_spec(camera(f"model: {name}"))
    assert spec.cameras["c"].model == name
    assert len(spec.cameras["c"].dist) == MODELS[name].dist_lengths[0]


def test_camera_model_accepts_exactly_the_registry():
    assert field_info(m.CameraSpec, "model").meta.choices == MODEL_NAMES
    with pytest.raises(SpecError) as info:
        parse_spec(camera("model: kannala_brandt"), file="s.yaml")
    assert "expected one of " + ", ".join(repr(n) for n in MODEL_NAMES) in info.value.message


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_dist_takes_exactly_the_registry_lengths(name):
    accepted = set()
    for n in range(15):
        values = ", ".join(["0"] * n)
        try:
            spec = parse_spec(camera(f"model: {name}", f"    dist: [{values}]\n"))
        except SpecError as e:
            assert e.field == "cameras.c.dist", str(e)
            continue
        assert len(spec.cameras["c"].dist) == n
        accepted.add(n)
    assert accepted == set(MODELS[name].dist_lengths)


def test_thin_lens_is_refused_on_wide_angle_models_only():
    lens = "    lens: {f_number: 2, focus_distance_m: 1, pixel_pitch_um: 3}\n"
    for name, cm in MODELS.items():
        if cm.wide_angle:
            with pytest.raises(SpecError, match="the thin lens is for perspective models"):
                parse_spec(camera(f"model: {name}", lens))
        else:
            assert parse_spec(camera(f"model: {name}", lens)).cameras["c"].optics.lens


def test_bit_depths_are_the_colour_module_s():
    assert field_info(m.RenderSettings, "bit_depth").meta.choices == BIT_DEPTHS
