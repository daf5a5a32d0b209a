"""Scene spec: parsing the examples, resolved poses against planted geometry, determinism."""
from __future__ import annotations

import json
import math
import pickle
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from scenegen.geometry.rotation import matrix_from_quat_wxyz
from scenegen.errors import SpecError
from scenegen.geometry.pose import Rigid3, camera_center, look_at
from scenegen.geometry.rotation import rotation_from_euler_deg
from scenegen.spec import (
    CameraSpec, DiffuseMaterial, PlasticMaterial, SceneSpec, View, load_spec, parse_spec,
    resolve_views, spec_sha256, spec_to_dict,
)

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = sorted((ROOT / "scenes" / "examples").glob("*.yaml"))
# Poses are compositions of a few float64 rotations: errors stay within ~1e-15 per operation;
# 1e-12 leaves room for a handful of products and inversions.
POSE_ATOL = 1e-12

CAMERA = """
cameras:
  cam: {size: [640, 480], fov_deg: 60}
"""


def parse(*parts: str, **kw) -> SceneSpec:
    """Parse the concatenation of YAML snippets, each dedented on its own."""
    return parse_spec("\n".join(textwrap.dedent(p) for p in parts), file="test.yaml", **kw)


def project(cam: CameraSpec, cam_from_world: Rigid3, points_world) -> np.ndarray:
    """Pinhole projection (no distortion) of (N, 3) world points -> (N, 2) OpenCV pixels."""
    p = cam_from_world.apply(np.atleast_2d(points_world))  # (N, 3)
    uvw = p @ cam.K.T
    return uvw[:, :2] / uvw[:, 2:]


# ---------------------------------------------------------------------------------------------
class TestExamples:
    @pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
    def test_example_parses_and_resolves(self, path):
        spec = load_spec(path)
        views = resolve_views(spec)
        assert views and len({v.name for v in views}) == len(views)
        assert all(v.camera in spec.cameras for v in views)
        d = spec_to_dict(spec)
        json.dumps(d, allow_nan=False)  # JSON-able
        assert [v["name"] for v in d["views"]] == [v.name for v in views]
        assert spec.warnings == ()

    def test_there_are_examples(self):
        assert len(EXAMPLES) >= 3

    def test_hash_is_stable_across_loads(self):
        a, b = (spec_sha256(load_spec(EXAMPLES[0])) for _ in range(2))
        assert a == b and len(a) == 64

    def test_hash_does_not_depend_on_location(self, tmp_path):
        text = EXAMPLES[0].read_text()
        (tmp_path / "copy.yaml").write_text(text)
        assert spec_sha256(load_spec(tmp_path / "copy.yaml")) == spec_sha256(load_spec(EXAMPLES[0]))

    def test_hash_changes_with_content(self):
        a = parse(CAMERA + "views: [{camera: cam, orbit: {radius_m: 2, count: 4}}]")
        b = parse(CAMERA + "views: [{camera: cam, orbit: {radius_m: 2.001, count: 4}}]")
        assert spec_sha256(a) != spec_sha256(b)


class TestDefaults:
    def test_empty_sections(self):
        spec = parse("name: empty\n")
        assert spec.name == "empty" and spec.objects == () and resolve_views(spec) == ()
        r = spec.render
        assert (r.spp, r.max_depth, r.seed, r.variant, r.bit_depth, r.sampler) == (
            64, 6, 0, "auto", 8, "ldsampler")

    def test_name_defaults_to_file_stem(self, tmp_path):
        (tmp_path / "my_scene.yaml").write_text("seed: 1\n")
        assert load_spec(tmp_path / "my_scene.yaml").name == "my_scene"

    def test_spp_the_sampler_rounds_up_is_kept_without_a_warning(self):
        # validate and the render summary state the rounding (tests/scenegen/render/test_render.py)
        spec = parse("render: {spp: 100}\n")
        assert spec.render.spp == 100 and spec.warnings == ()

    def test_yaml_11_exponent_without_dot_is_a_number(self):
        spec = parse("objects: [{name: s, shape: {type: sphere, radius: 1e-3}}]\n")
        assert spec.objects[0].geometry.radius == pytest.approx(1e-3)

    def test_anchors_and_merge_keys(self):
        spec = parse("""
            materials:
              base: &base {type: plastic, color: [0.1, 0.2, 0.3], roughness: 0.3}
              shiny: {<<: *base, roughness: 0.01}
            objects:
              - {name: a, shape: sphere, material: shiny}
              - {name: b, shape: sphere, material: base}
            """)
        a, b = (o.material for o in spec.objects)
        assert isinstance(a, PlasticMaterial) and a.roughness == 0.01 and a.color == (0.1, 0.2, 0.3)
        assert b.roughness == 0.3

    def test_default_material_and_ids(self):
        spec = parse("""
            objects:
              - {name: a, shape: sphere}
              - {name: b, shape: box, instance_id: 7}
            """)
        a, b = spec.objects
        assert isinstance(a.material, DiffuseMaterial) and a.material.color == (0.5, 0.5, 0.5)
        assert (a.object_id, a.instance_id, b.object_id, b.instance_id) == (1, 1, 2, 7)

    def test_default_seeds_differ_between_things_and_follow_scene_seed(self):
        text = """
            seed: {s}
            materials:
              a: {{type: diffuse, texture: {{type: noise}}}}
              b: {{type: diffuse, texture: {{type: noise}}}}
            """
        s1, s2 = parse(text.format(s=1)), parse(text.format(s=2))
        assert s1.materials["a"].texture.seed != s1.materials["b"].texture.seed
        assert s1.materials["a"].texture.seed != s2.materials["a"].texture.seed
        assert s1.materials["a"].texture.seed == parse(text.format(s=1)).materials["a"].texture.seed


class TestFiles:
    def test_mesh_path_resolves_relative_to_spec(self, tmp_path):
        (tmp_path / "assets").mkdir()
        (tmp_path / "assets" / "tri.ply").write_text(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
        (tmp_path / "scene.yaml").write_text("objects: [{name: tri, mesh: assets/tri.ply}]\n")
        obj = load_spec(tmp_path / "scene.yaml").objects[0]
        assert obj.geometry.path == (tmp_path / "assets" / "tri.ply").resolve()
        d = spec_to_dict(load_spec(tmp_path / "scene.yaml"))
        assert d["objects"][0]["geometry"]["path"]["path"] == "assets/tri.ply"
        assert len(d["objects"][0]["geometry"]["path"]["sha256"]) == 64

    def test_missing_spec_file(self, tmp_path):
        with pytest.raises(SpecError, match="cannot read the spec file"):
            load_spec(tmp_path / "nope.yaml")


class TestTransforms:
    def test_euler_matches_pose_helper_and_quaternion(self):
        spec = parse("""
            objects:
              - name: a
                shape: sphere
                transform: {translation: [1, 2, 3], rotation_deg: [10, 20, 30], order: ZYX,
                            scale: 2}
              - name: b
                shape: sphere
                transform: {rotation_quat_wxyz: [0.5, 0.5, 0.5, 0.5]}
            """)
        a, b = spec.objects
        np.testing.assert_allclose(a.transform.world_from_object.R,
                                   rotation_from_euler_deg([10, 20, 30], "ZYX"), atol=POSE_ATOL)
        np.testing.assert_array_equal(a.transform.world_from_object.t, [1, 2, 3])
        assert a.transform.scale == (2.0, 2.0, 2.0)
        np.testing.assert_allclose(a.transform.matrix[:3, :3],
                                   2 * a.transform.world_from_object.R, atol=POSE_ATOL)
        np.testing.assert_allclose(b.transform.world_from_object.R,
                                   matrix_from_quat_wxyz([0.5, 0.5, 0.5, 0.5]), atol=POSE_ATOL)


# ---------------------------------------------------------------------------------------------
class TestCameras:
    def test_fov_gives_pixel_centre_convention(self):
        cam = parse(CAMERA).cameras["cam"]
        f = 320 / math.tan(math.radians(30))
        assert (cam.fx, cam.fy, cam.cx, cam.cy, cam.skew) == pytest.approx((f, f, 319.5, 239.5, 0))
        assert cam.dist == () and cam.model == "pinhole" and cam.size == (640, 480)

    def test_fov_agrees_with_camera_module(self):
        import scenegen.geometry.camera as camera
        cam = parse(CAMERA).cameras["cam"]
        ref = camera.Camera.from_fov(60, (640, 480))
        assert (cam.fx, cam.fy, cam.cx, cam.cy) == pytest.approx((ref.fx, ref.fy, ref.cx, ref.cy),
                                                                 rel=1e-15)
        assert cam.to_camera() == ref

    def test_explicit_intrinsics_and_default_distortion(self):
        spec = parse("""
            cameras:
              a: {model: opencv, size: [100, 80], fx: 90, fy: 95, cx: 50, cy: 40, skew: 0.5}
              b: {model: fisheye, size: [100, 80], fx: 30}
            """)
        a, b = spec.cameras["a"], spec.cameras["b"]
        assert a.dist == (0.0,) * 4 and b.dist == (0.0,) * 4
        np.testing.assert_array_equal(a.K, [[90, 0.5, 50], [0, 95, 40], [0, 0, 1]])
        assert (b.fy, b.cx, b.cy) == (30.0, 49.5, 39.5)  # fy defaults to fx, centre to the middle


# ---------------------------------------------------------------------------------------------
STEREO = """
cameras:
  L: {size: [640, 480], fx: 500}
  R: {size: [640, 480], fx: 510}
rigs:
  st: {type: stereo, left: L, right: R, baseline_m: 0.25, vergence_deg: %s}
views:
  - rig: st
    look_at: [{eye: [1, -2, 1.5], target: [0, 0, 0.5]}, {eye: [-2, 0.5, 1], target: [0, 0, 0]}]
"""


class TestStereoRig:
    @pytest.mark.parametrize("vergence_deg", [0.0, 4.0, 30.0])
    def test_right_centre_at_baseline_and_half_vergence_each(self, vergence_deg):
        spec = parse(STEREO % vergence_deg)
        views = resolve_views(spec)
        assert [v.name for v in views] == ["st_left_0000", "st_right_0000",
                                           "st_left_0001", "st_right_0001"]
        assert [v.frame_index for v in views] == [0, 0, 1, 1]
        assert [v.rig_member for v in views] == ["left", "right"] * 2
        assert [v.camera for v in views] == ["L", "R"] * 2
        half = math.radians(vergence_deg) / 2
        for k, eye, target in [(0, [1, -2, 1.5], [0, 0, 0.5]), (1, [-2, 0.5, 1], [0, 0, 0])]:
            left, right = views[2 * k], views[2 * k + 1]
            world_from_rig = look_at(eye, target)
            # left camera centre = rig origin = eye; right centre at (+baseline, 0, 0) in the rig
            np.testing.assert_allclose(camera_center(left.cam_from_world), eye, atol=POSE_ATOL)
            rig_from_world = world_from_rig.inverse()
            np.testing.assert_allclose(rig_from_world.apply(camera_center(right.cam_from_world)),
                                       [0.25, 0, 0], atol=POSE_ATOL)
            # optical axes in the rig frame: turned by +-half about y, toward each other
            z_left = rig_from_world.rotate(left.cam_from_world.inverse().rotate([0, 0, 1]))
            z_right = rig_from_world.rotate(right.cam_from_world.inverse().rotate([0, 0, 1]))
            np.testing.assert_allclose(z_left, [math.sin(half), 0, math.cos(half)], atol=1e-12)
            np.testing.assert_allclose(z_right, [-math.sin(half), 0, math.cos(half)], atol=1e-12)
            # y axes stay those of the rig (rotation about y only)
            y_left = rig_from_world.rotate(left.cam_from_world.inverse().rotate([0, 1, 0]))
            np.testing.assert_allclose(y_left, [0, 1, 0], atol=1e-12)
            if vergence_deg:
                # the optical axes meet at distance (b/2) / tan(half) in front of the midpoint
                meet = world_from_rig.apply([0.125, 0, 0.125 / math.tan(half)])
                for v in (left, right):
                    p = v.cam_from_world.apply(meet)
                    np.testing.assert_allclose(p[:2], 0, atol=1e-9)

    def test_same_camera_both_sides(self):
        text = (STEREO % 0).replace("right: R", "right: L")
        views = resolve_views(parse(text))
        assert {v.camera for v in views} == {"L"}


class TestMultiRig:
    def test_world_from_cam_is_world_from_rig_times_rig_from_cam(self):
        spec = parse("""
            cameras:
              a: {size: [64, 48], fx: 50}
              b: {size: [64, 48], fx: 50}
            rigs:
              trio:
                type: multi
                members:
                  - {camera: a}
                  - {camera: b, rig_from_cam: {translation: [0.1, 0, 0], rotation_deg: [0, 20, 0]}}
                  - camera: a
                    name: a2
                    rig_from_cam: [[1, 0, 0, -0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
            views:
              - rig: trio
                poses:
                  - world_from_rig: {translation: [1, 2, 3], rotation_deg: [0, 0, 90]}
            """)
        views = resolve_views(spec)
        assert [v.name for v in views] == ["trio_a_0000", "trio_b_0000", "trio_a2_0000"]
        world_from_rig = Rigid3(rotation_from_euler_deg([0, 0, 90]), [1, 2, 3])
        for v, member in zip(views, spec.rigs["trio"].members):
            expected = (world_from_rig @ member.rig_from_cam).inverse()
            assert v.cam_from_world.allclose(expected, atol=POSE_ATOL)
        np.testing.assert_allclose(camera_center(views[1].cam_from_world),
                                   world_from_rig.apply([0.1, 0, 0]), atol=POSE_ATOL)


# ---------------------------------------------------------------------------------------------
class TestPlacements:
    def test_orbit_looks_at_centre(self):
        spec = parse(CAMERA, """
            views:
              - camera: cam
                orbit: {center: [0.3, -0.2, 0.5], radius_m: 2.5, elevations_deg: [-30, 0, 15, 80],
                        count: 7, start_azimuth_deg: 10}
            """)
        cam, views = spec.cameras["cam"], resolve_views(spec)
        assert len(views) == 28 and views[-1].name == "cam_0027"
        center = np.array([0.3, -0.2, 0.5])
        for k, v in enumerate(views):
            np.testing.assert_allclose(project(cam, v.cam_from_world, center)[0], [cam.cx, cam.cy],
                                       atol=1e-9)
            c = camera_center(v.cam_from_world)
            assert np.linalg.norm(c - center) == pytest.approx(2.5, abs=1e-12)
            el = [-30, 0, 15, 80][k // 7]
            az = 10 + 360 * (k % 7) / 7
            assert math.degrees(math.asin((c[2] - 0.5) / 2.5)) == pytest.approx(el, abs=1e-9)
            assert math.degrees(math.atan2(c[1] + 0.2, c[0] - 0.3)) % 360 == pytest.approx(
                az % 360, abs=1e-9)
            # world up appears up in the image: z axis maps to negative image y
            assert v.cam_from_world.rotate([0, 0, 1])[1] < 0

    def test_look_at_and_explicit_poses(self):
        spec = parse(CAMERA, """
            views:
              - camera: cam
                look_at: [{eye: [3, 0, 1], target: [0, 0, 1], up: [0, 0, 1]}]
              - name: explicit
                camera: cam
                poses:
                  - world_from_cam: {translation: [1, 2, 3], rotation_quat_wxyz: [0, 1, 0, 0]}
                  - cam_from_world: {translation: [1, 2, 3], rotation_quat_wxyz: [0, 1, 0, 0]}
                  - world_from_cam: [[1, 0, 0, 1], [0, 1, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]]
            """)
        views = resolve_views(spec)
        assert [v.name for v in views] == ["cam_0000", "explicit_0001", "explicit_0002",
                                           "explicit_0003"]
        np.testing.assert_allclose(camera_center(views[0].cam_from_world), [3, 0, 1])
        T = Rigid3(np.diag([1.0, -1.0, -1.0]), [1, 2, 3])
        assert views[1].cam_from_world.allclose(T.inverse(), atol=POSE_ATOL)
        assert views[2].cam_from_world.allclose(T, atol=POSE_ATOL)
        assert views[3].cam_from_world.allclose(Rigid3(np.eye(3), [1, 2, 3]).inverse())

    def test_line_and_circle_paths(self):
        spec = parse(CAMERA, """
            views:
              - camera: cam
                path: {line: {from: [-1, -3, 1], to: [1, -3, 2]}, count: 5, target: [0, 0, 0]}
              - camera: cam
                path: {circle: {center: [0, 0, 0.5], radius_m: 2, height_m: 1}, count: 8}
            """)
        cam, views = spec.cameras["cam"], resolve_views(spec)
        centres = np.array([camera_center(v.cam_from_world) for v in views])
        np.testing.assert_allclose(centres[:5], np.linspace([-1, -3, 1], [1, -3, 2], 5),
                                   atol=1e-12)
        circ = centres[5:]
        np.testing.assert_allclose(np.hypot(circ[:, 0], circ[:, 1]), 2, atol=1e-12)
        np.testing.assert_allclose(circ[:, 2], 1.5, atol=1e-12)
        np.testing.assert_allclose(circ[2], [0, 2, 1.5], atol=1e-12)  # 90 degrees per 2 steps
        for v, tgt in zip(views, [[0, 0, 0]] * 5 + [[0, 0, 0.5]] * 8):
            np.testing.assert_allclose(project(cam, v.cam_from_world, tgt)[0], [cam.cx, cam.cy],
                                       atol=1e-9)

    RANDOM = """
        seed: %d
        views:
          - camera: cam
            random:
              count: 50
              %s
              eye_box: {min: [-2, -2, 0.5], max: [2, 2, 2]}
              target_box: {min: [-0.1, -0.1, 0], max: [0.1, 0.1, 0.2]}
              min_distance_m: 1.0
        """

    def test_random_views_reproducible_and_in_bounds(self):
        a = resolve_views(parse(CAMERA, self.RANDOM % (0, "seed: 5")))
        b = resolve_views(parse(CAMERA, self.RANDOM % (99, "seed: 5")))  # explicit seed wins
        c = resolve_views(parse(CAMERA, self.RANDOM % (0, "seed: 6")))
        assert all(x.cam_from_world.allclose(y.cam_from_world, atol=0) for x, y in zip(a, b))
        assert not a[0].cam_from_world.allclose(c[0].cam_from_world, atol=1e-6)
        centres = np.array([camera_center(v.cam_from_world) for v in a])
        assert np.all(centres >= [-2, -2, 0.5]) and np.all(centres <= [2, 2, 2])
        assert np.all(np.linalg.norm(centres - [0, 0, 0.1], axis=1) >= 1.0 - 0.2)

    def test_random_default_seed_follows_scene_seed(self):
        a = resolve_views(parse(CAMERA, self.RANDOM % (1, "")))
        b = resolve_views(parse(CAMERA, self.RANDOM % (1, "")))
        c = resolve_views(parse(CAMERA, self.RANDOM % (2, "")))
        assert all(x.cam_from_world.allclose(y.cam_from_world, atol=0) for x, y in zip(a, b))
        assert not a[0].cam_from_world.allclose(c[0].cam_from_world, atol=1e-6)

    def test_frame_index_counts_over_view_sets(self):
        spec = parse(STEREO % 0 + "  - {camera: L, orbit: {radius_m: 2, count: 3}}\n")
        views = resolve_views(spec)
        assert [v.frame_index for v in views] == [0, 0, 1, 1, 2, 3, 4]
        assert [v.name for v in views][4:] == ["L_0002", "L_0003", "L_0004"]
        assert [v.view_set for v in views] == [0, 0, 0, 0, 1, 1, 1]
        assert all(isinstance(v, View) for v in views)


# ---------------------------------------------------------------------------------------------
class TestErrorObject:
    def test_str_and_pickle(self):
        e = SpecError("expected 3 numbers (degrees), got 'abc'", file="scene.yaml", line=14,
                      field="objects[2].transform.rotation_deg")
        assert str(e) == ("scene.yaml:14: objects[2].transform.rotation_deg: expected 3 numbers "
                          "(degrees), got 'abc'")
        e2 = pickle.loads(pickle.dumps(e))
        assert (str(e2), e2.line, e2.field) == (str(e), 14, e.field)
        assert str(SpecError("boom")) == "boom"
        assert str(SpecError("boom", file="a.yaml")) == "a.yaml: boom"

    def test_camera_where_points_into_the_file(self):
        spec = parse("\n\ncameras:\n  cam: {size: [64, 48], fx: 50}\n")
        w = spec.cameras["cam"].where
        assert (w.file, w.line, w.field) == ("test.yaml", 4, "cameras.cam")


def test_spec_layer_does_not_import_mitsuba():
    code = ("import sys; from scenegen.spec import load_spec, resolve_views, spec_to_dict;"
            f"s = load_spec({str(EXAMPLES[0])!r}); resolve_views(s); spec_to_dict(s);"
            "bad = [m for m in ('mitsuba', 'drjit') if m in sys.modules]; assert not bad, bad")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def test_docs_complete_example_parses(tmp_path):
    doc = (ROOT / "docs" / "scene_spec.md").read_text()
    text = doc.split("## Complete example")[1].split("```yaml\n")[1].split("```")[0]
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "bunny.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    (tmp_path / "demo.yaml").write_text(text)
    spec = load_spec(tmp_path / "demo.yaml")
    views = resolve_views(spec)
    assert len(views) == 24 + 2 * 5 + 2 * 10 + 1
    assert views[24].name == "stereo_left_0024" and views[-1].name == "closeup_0039"
