"""Malformed specs: each must fail with a SpecError naming the file, line and field path, and a
message that says what was expected."""
from __future__ import annotations

import textwrap

import pytest

from scenegen.errors import SpecError
from scenegen.spec import load_spec, parse_spec

CAM = "cameras:\n  cam: {size: [640, 480], fov_deg: 60}\n"
# two named lights and a view set whose `lights:` the rows below append (line 9 on)
LIT = (CAM + "lights:\n  - {type: area, name: key_light, position: [0, -1, 2], look_at: [0, 0, 0], "
       "radiance: 5}\n  - {type: point, name: fill, position: [1, 1, 1], intensity: 2}\n"
       "views:\n  - camera: cam\n    look_at: [{eye: [0, -2, 1], target: [0, 0, 0]}]\n")

# (id, spec text, line, field path (None: none), message fragment)
CASES = [
    ("lens_on_fisheye",
     "cameras:\n  f:\n    model: fisheye\n    size: [64, 64]\n    fx: 30\n    dist: [0, 0, 0, 0]\n"
     "    lens: {f_number: 2, focus_distance_m: 1, pixel_pitch_um: 3}\n",
     7, "cameras.f.lens", "the thin lens is for perspective models"),
    ("lens_missing_pitch",
     "cameras:\n  c:\n    size: [64, 64]\n    fx: 30\n    lens: {f_number: 2, focus_distance_m: 1}\n",
     5, "cameras.c.lens.pixel_pitch_um", "missing required key 'pixel_pitch_um'"),
    ("negative_exposure",
     "cameras:\n  c:\n    size: [64, 64]\n    fx: 30\n    shutter: {exposure_s: -0.01}\n",
     5, "cameras.c.shutter.exposure_s", "seconds"),
    ("unknown_shutter_key_suggests",
     "cameras:\n  c:\n    size: [64, 64]\n    fx: 30\n    shutter: {rolling_readout: 0.01}\n",
     5, "cameras.c.shutter.rolling_readout", "(did you mean 'rolling_readout_s'?)"),
    ("motion_wrong_length",
     CAM + "views:\n  - camera: cam\n    motion: {linear_velocity_mps: [1, 0]}\n"
     "    orbit: {radius_m: 2, count: 4}\n",
     5, "views[0].motion.linear_velocity_mps", "expected 3 numbers (metres / second)"),
    ("chromatic_scale_out_of_range",
     "cameras:\n  c:\n    size: [64, 64]\n    fx: 30\n    chromatic_aberration: {red_focal_scale: 3}\n",
     5, "cameras.c.chromatic_aberration.red_focal_scale", "2"),
    ("unknown_top_level_key_suggests",
     "name: x\nobject:\n  - {name: a, shape: sphere}\n",
     2, "object", "unknown key 'object' (did you mean 'objects'?)"),
    ("unknown_nested_key_suggests",
     "objects:\n  - name: a\n    shape: {type: sphere, radus: 1}\n",
     3, "objects[0].shape.radus", "(did you mean 'radius'?)"),
    ("wrong_type_rotation",
     "objects:\n  - name: a\n    shape: sphere\n    transform:\n      rotation_deg: abc\n",
     5, "objects[0].transform.rotation_deg", "expected 3 numbers (degrees), got 'abc'"),
    ("wrong_length_translation",
     "objects:\n  - name: a\n    shape: sphere\n    transform: {translation: [1, 2]}\n",
     4, "objects[0].transform.translation", "expected 3 numbers (metres), got 2 numbers"),
    ("missing_required_name",
     "objects:\n  - shape: sphere\n    material: {type: diffuse}\n",
     2, "objects[0].name", "missing required key 'name'"),
    ("missing_geometry",
     "objects:\n  - name: a\n",
     2, "objects[0]", "expected one of the keys shape, mesh, target"),
    ("bad_enum_variant_suggests",
     "render:\n  spp: 16\n  variant: llvm_rgb\n",
     3, "render.variant", "got 'llvm_rgb' (did you mean 'llvm_ad_rgb'?)"),
    ("bad_enum_sampler",
     "render: {sampler: sobol}\n",
     1, "render.sampler", "expected one of 'ldsampler', 'multijitter'"),
    ("bad_bit_depth",
     "render: {bit_depth: 12}\n",
     1, "render.bit_depth", "expected one of 8, 16"),
    ("spp_not_integer",
     "render:\n  spp: 6.5\n",
     2, "render.spp", "expected an integer (samples per pixel), got 6.5"),
    ("missing_mesh_file",
     "objects:\n  - name: m\n    mesh: meshes/bunny.ply\n",
     3, "objects[0].mesh", "file not found: 'meshes/bunny.ply'"),
    ("mesh_wrong_format",
     "objects:\n  - name: m\n    mesh: bunny.fbx\n",
     3, "objects[0].mesh", "expected a mesh file (.ply, .obj, .glb, .gltf, .stl)"),
    ("missing_texture_image",
     "materials:\n  wood:\n    type: diffuse\n    texture: {type: image, path: wood.png}\n",
     4, "materials.wood.texture.path", "file not found: 'wood.png'"),
    ("undefined_material_suggests",
     "materials:\n  red_plastic: {type: plastic}\nobjects:\n  - name: a\n    shape: sphere\n"
     "    material: red_plastc\n",
     6, "objects[0].material", "undefined material 'red_plastc' (did you mean 'red_plastic'?)"),
    ("undefined_camera_in_view",
     CAM + "views:\n  - camera: cma\n    orbit: {radius_m: 2, count: 4}\n",
     4, "views[0].camera", "undefined camera 'cma' (did you mean 'cam'?)"),
    ("undefined_camera_in_rig",
     CAM + "rigs:\n  st: {type: stereo, left: cam, right: camR, baseline_m: 0.1}\n",
     4, "rigs.st.right", "undefined camera 'camR'"),
    ("undefined_rig",
     CAM + "views:\n  - rig: stereo\n    orbit: {radius_m: 2, count: 4}\n",
     4, "views[0].rig", "undefined rig 'stereo'"),
    ("both_rotation_forms",
     "objects:\n  - name: a\n    shape: sphere\n    transform:\n      rotation_deg: [0, 0, 90]\n"
     "      rotation_quat_wxyz: [1, 0, 0, 0]\n",
     6, "objects[0].transform.rotation_quat_wxyz",
     "give only one of rotation_deg, rotation_quat_wxyz"),
    ("negative_size",
     "objects:\n  - name: a\n    shape: {type: box, size: [1, -2, 1]}\n",
     3, "objects[0].shape.size[1]", "expected a value > 0 (metres), got -2"),
    ("negative_radius",
     "objects:\n  - name: a\n    shape:\n      type: sphere\n      radius: -0.5\n",
     5, "objects[0].shape.radius", "expected a value > 0 (metres)"),
    ("camera_size_not_integer",
     "cameras:\n  cam:\n    size: [640.5, 480]\n    fx: 500\n",
     3, "cameras.cam.size[0]", "expected a positive whole number of pixels"),
    ("camera_negative_focal",
     "cameras:\n  cam:\n    size: [640, 480]\n    fx: -500\n",
     4, "cameras.cam.fx", "expected a value > 0 (pixels)"),
    ("camera_fov_and_fx",
     "cameras:\n  cam:\n    size: [640, 480]\n    fov_deg: 60\n    fx: 500\n",
     5, "cameras.cam.fx", "give either fov_deg or fx and fy"),
    ("wrong_dist_length_opencv",
     "cameras:\n  cam:\n    model: opencv\n    size: [640, 480]\n    fx: 500\n"
     "    dist: [0.1, 0.01, 0.0]\n",
     6, "cameras.cam.dist", "expected 4, 5, 8 or 12 numbers"),
    ("wrong_dist_length_fisheye",
     "cameras:\n  cam: {model: fisheye, size: [640, 480], fx: 300, dist: [0.1, 0.2, 0.3, 0.4, 0.5]}\n",
     2, "cameras.cam.dist", "expected 4 numbers (fisheye coefficients k1, k2, k3, k4)"),
    ("pinhole_with_dist",
     "cameras:\n  cam:\n    size: [640, 480]\n    fx: 500\n    dist: [0.1, 0, 0, 0]\n",
     5, "cameras.cam.dist", "a pinhole camera has no distortion"),
    ("duplicate_object_names",
     "objects:\n  - name: cube\n    shape: box\n  - name: ball\n    shape: sphere\n"
     "  - name: cube\n    shape: box\n",
     6, "objects[2].name", "duplicate object name 'cube' (first at line 2)"),
    ("duplicate_yaml_key",
     "seed: 1\nrender: {spp: 4}\nseed: 2\n",
     3, "seed", "duplicate key 'seed' (first given at line 1)"),
    ("invalid_yaml_syntax",
     "name: x\nobjects:\n  - name: a\n    shape: {type: sphere\n",
     5, None, "invalid YAML"),
    ("invalid_yaml_tab_indent",
     "name: x\nrender:\n\tspp: 4\n",
     3, None, "invalid YAML"),
    ("non_mapping_root",
     "- name: a\n- name: b\n",
     1, None, "expected a mapping at the top level"),
    ("empty_document",
     "# nothing but a comment\n",
     1, None, "got an empty document"),
    ("non_string_key",
     "objects:\n  - name: a\n    shape: sphere\n    1: 2\n",
     4, "objects[0]", "expected a string key, got 1"),
    ("bool_is_not_a_number",
     "seed: true\n",
     1, "seed", "expected an integer, got True"),
    ("nan_is_not_finite",
     "objects:\n  - name: a\n    shape: {type: sphere, radius: .nan}\n",
     3, "objects[0].shape.radius", "expected a finite number"),
    ("torus_minor_too_big",
     "objects:\n  - name: t\n    shape: {type: torus, major_radius: 0.2, minor_radius: 0.3}\n",
     3, "objects[0].shape.minor_radius", "expected minor_radius < major_radius"),
    ("charuco_marker_bigger_than_square",
     "objects:\n  - name: b\n    target:\n      type: charuco\n      squares_x: 5\n      squares_y: 4\n"
     "      square_m: 0.04\n      marker_m: 0.05\n      dictionary: DICT_4X4_50\n",
     8, "objects[0].target.marker_m", "expected marker_m < square_m"),
    ("aruco_dictionary_unknown",
     "objects:\n  - name: b\n    target: {type: aruco_grid, markers_x: 2, markers_y: 2, "
     "marker_m: 0.05,\n             separation_m: 0.01, dictionary: DICT_5X5_10}\n",
     4, "objects[0].target.dictionary", "(did you mean 'DICT_5X5_100'?)"),
    ("view_needs_camera_or_rig",
     CAM + "views:\n  - orbit: {radius_m: 2, count: 4}\n",
     4, "views[0]", "expected one of the keys camera, rig"),
    ("view_two_placements",
     CAM + "views:\n  - camera: cam\n    orbit: {radius_m: 2, count: 4}\n"
     "    look_at: [{eye: [1, 0, 0], target: [0, 0, 0]}]\n",
     6, "views[0].look_at", "give only one of orbit, look_at, poses, random, path"),
    ("look_at_along_up",
     CAM + "views:\n  - camera: cam\n    look_at:\n      - {eye: [0, 0, 2], target: [0, 0, 0]}\n",
     6, "views[0].look_at[0]", "parallel to the up vector"),
    ("orbit_elevation_90",
     CAM + "views:\n  - camera: cam\n    orbit: {radius_m: 2, count: 4, elevations_deg: [30, 90]}\n",
     5, "views[0].orbit.elevations_deg[1]", "strictly between -90 and 90 degrees"),
    ("camera_pose_key_in_rig_view",
     CAM + "rigs:\n  st: {type: stereo, left: cam, right: cam, baseline_m: 0.1}\nviews:\n"
     "  - rig: st\n    poses:\n      - world_from_cam: {translation: [0, 0, 1]}\n",
     8, "views[0].poses[0].world_from_cam", "use world_from_rig or rig_from_world"),
    ("pose_matrix_not_rigid",
     CAM + "views:\n  - camera: cam\n    poses:\n      - cam_from_world:\n"
     "          [[2, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n",
     7, "views[0].poses[0].cam_from_world", "rotation must be orthonormal"),
    ("random_box_inverted",
     CAM + "views:\n  - camera: cam\n    random:\n      count: 3\n"
     "      eye_box: {min: [0, 0, 1], max: [1, -1, 2]}\n      target: [0, 0, 0]\n",
     7, "views[0].random.eye_box.max", "expected max >= min on every axis"),
    ("color_out_of_range",
     "materials:\n  m: {type: diffuse, color: [0.5, 1.5, 0.2]}\n",
     2, "materials.m.color", "expected reflectance in [0, 1]"),
    ("unknown_conductor",
     "materials:\n  m: {type: conductor, material: Alu}\n",
     2, "materials.m.material", "unknown conductor 'Alu'"),
    ("texture_kind_unknown",
     "materials:\n  m:\n    type: diffuse\n    texture: {type: perlin}\n",
     4, "materials.m.texture.type", "expected one of 'image', 'checkerboard'"),
    ("texture_params_not_mapping",
     "materials:\n  m:\n    type: diffuse\n    texture: {type: noise, params: [1, 2]}\n",
     4, "materials.m.texture.params", "expected a mapping of texture parameters"),
    ("spot_cutoff_out_of_range",
     "lights:\n  - {type: spot, position: [0, 0, 2], target: [0, 0, 0], intensity: 5, "
     "cutoff_deg: 120}\n",
     2, "lights[0].cutoff_deg", "expected a value > 0 and <= 90 (degrees)"),
    ("bad_euler_order",
     "objects:\n  - name: a\n    shape: sphere\n    transform: {rotation_deg: [1, 2, 3], order: xxz}\n",
     4, "objects[0].transform.order", "no axis twice in a row"),
    ("bad_name_characters",
     "cameras:\n  my cam: {size: [64, 48], fx: 50}\n",
     2, "cameras.my cam", "expected a camera name made of letters, digits"),
    # cameras.<name>.imaging (docs/image_formation.md)
    ("imaging_unknown_preset_suggests",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging: {preset: smartfone}\n",
     5, "cameras.cam.imaging.preset", "got 'smartfone' (did you mean 'smartphone'?)"),
    ("imaging_unknown_key",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      exposure_s: 0.01\n",
     6, "cameras.cam.imaging.exposure_s", "unknown key 'exposure_s'"),
    ("imaging_negative_exposure_time",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      exposure:\n"
     "        exposure_time_s: -0.01\n",
     7, "cameras.cam.imaging.exposure.exposure_time_s", "expected a value > 0 (seconds)"),
    ("imaging_qe_above_one",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      sensor:\n"
     "        quantum_efficiency: [0.5, 1.2, 0.5]\n",
     7, "cameras.cam.imaging.sensor.quantum_efficiency[1]", "expected a value >= 0 and <= 1"),
    ("imaging_vignetting_coeffs_length",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n"
     "      vignetting: {coeffs: [-0.3, 0.1]}\n",
     6, "cameras.cam.imaging.vignetting.coeffs", "expected 3 numbers"),
    ("imaging_bad_bayer_pattern",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging: {bayer: RGBG}\n",
     5, "cameras.cam.imaging.bayer", "expected one of 'RGGB', 'BGGR', 'GRBG', 'GBRG', 'none'"),
    ("imaging_adc_bits_too_many",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      sensor:\n"
     "        adc_bits: 20\n",
     7, "cameras.cam.imaging.sensor.adc_bits", "expected a value >= 1 and <= 16 (bits)"),
    ("imaging_black_level_above_white",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      preset: smartphone\n"
     "      sensor:\n        black_level_dn: 1023\n",
     8, "cameras.cam.imaging.sensor.black_level_dn", "expected black_level_dn < 2^adc_bits - 1"),
    # imaging.raw (issue 19): opt-in raw mosaic files
    ("imaging_raw_without_bayer",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      preset: dslr\n"
     "      bayer: none\n      raw: true\n",
     7, "cameras.cam.imaging.bayer", "raw output is the colour filter mosaic; with bayer: none"),
    ("imaging_raw_default_camera_has_no_bayer",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging: {raw: true}\n",
     5, "cameras.cam.imaging.raw", "give a Bayer pattern, or remove raw"),
    ("imaging_raw_every_output_off",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      preset: dslr\n"
     "      raw: {dng: false}\n",
     7, "cameras.cam.imaging.raw", "every output (dng, png) is off"),
    ("imaging_raw_unknown_key",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      preset: dslr\n"
     "      raw: {tiff: true}\n",
     7, "cameras.cam.imaging.raw.tiff", "unknown key 'tiff'"),
    ("imaging_raw_not_a_flag",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      preset: dslr\n"
     "      raw: dng\n",
     7, "cameras.cam.imaging.raw", "expected true, false or a mapping {dng: true/false, png: true/false}"),
    ("imaging_raw_flag_not_bool",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      preset: dslr\n"
     "      raw: {png: 1}\n",
     7, "cameras.cam.imaging.raw.png", "expected true or false"),
    ("imaging_black_level_clip_not_bool",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging:\n      sensor:\n"
     "        black_level_clip: yes please\n",
     7, "cameras.cam.imaging.sensor.black_level_clip", "expected true or false"),
    ("imaging_bad_white_balance",
     "cameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n    imaging: {white_balance: daylight}\n",
     5, "cameras.cam.imaging.white_balance", "expected one of 'auto'"),
    # crossview (docs/crossview.md)
    ("crossview_unknown_key_suggests",
     CAM + "crossview:\n  pair: all\n",
     4, "crossview.pair", "unknown key 'pair' (did you mean 'pairs'?)"),
    ("crossview_bad_pair_mode",
     CAM + "crossview: {pairs: every}\n",
     3, "crossview.pairs", "expected one of 'consecutive', 'all', 'none'"),
    ("crossview_pair_undefined_view",
     CAM + "views:\n  - camera: cam\n    orbit: {radius_m: 2, count: 2}\ncrossview:\n"
     "  pairs:\n    - [cam_0000, cam_0005]\n",
     8, "crossview.pairs[0][1]", "undefined view 'cam_0005'"),
    ("crossview_pair_same_view",
     CAM + "views:\n  - camera: cam\n    orbit: {radius_m: 2, count: 2}\ncrossview:\n"
     "  pairs: [[cam_0000, cam_0000]]\n",
     7, "crossview.pairs[0][1]", "a pair needs two different views"),
    ("crossview_pair_three_views",
     CAM + "crossview:\n  pairs: [[a, b, c]]\n",
     4, "crossview.pairs[0]", "expected a pair [view_a, view_b] of view names, got 3 items"),
    ("crossview_outlier_fraction_one",
     CAM + "crossview:\n  matches: {count: 10, outlier_fraction: 1.0}\n",
     4, "crossview.matches.outlier_fraction", "expected a value >= 0 and < 1"),
    ("crossview_near_miss_inverted",
     CAM + "crossview:\n  matches:\n    near_miss_px: [10, 4]\n",
     5, "crossview.matches.near_miss_px", "expected min <= max"),
    ("crossview_flow_not_bool",
     CAM + "crossview: {flow: maybe}\n",
     3, "crossview.flow", "expected true or false"),
    ("crossview_sift_inlier_px_zero",
     CAM + "crossview: {sift: true, sift_inlier_px: 0}\n",
     3, "crossview.sift_inlier_px", "expected a value > 0 (pixels)"),
    # per-view-set lighting (views[i].lights)
    ("view_lights_unknown_name_suggests",
     LIT + "    lights: [key_lite]\n",
     9, "views[0].lights[0]",
     "undefined light 'key_lite' (did you mean 'key_light'?); defined under lights: key_light, fill"),
    ("view_lights_unknown_name_in_mapping",
     LIT + "    lights:\n      key_light: 1\n      fil: 0.5\n",
     11, "views[0].lights.fil", "undefined light 'fil' (did you mean 'fill'?)"),
    ("view_lights_negative_scale",
     LIT + "    lights: {key_light: -0.5}\n",
     9, "views[0].lights.key_light", "expected a value >= 0 (factor on the light's spec power), got -0.5"),
    ("view_lights_infinite_scale",
     LIT + "    lights: {fill: .inf}\n",
     9, "views[0].lights.fill", "expected a finite number"),
    ("view_lights_scale_not_a_number",
     LIT + "    lights: {fill: bright}\n",
     9, "views[0].lights.fill", "expected a number (factor on the light's spec power), got 'bright'"),
    ("view_lights_wrong_type",
     LIT + "    lights: key_light\n",
     9, "views[0].lights", "expected a list of light names (on at their spec power, the others off) "
                           "or a mapping of light names to factors >= 0, got 'key_light'"),
    ("view_lights_name_not_a_string",
     LIT + "    lights: [3]\n",
     9, "views[0].lights[0]", "expected a light name, got 3"),
    ("view_lights_duplicate_name",
     LIT + "    lights:\n      - fill\n      - key_light\n      - fill\n",
     12, "views[0].lights[2]", "duplicate light 'fill' (first at line 10)"),
    ("view_lights_empty",
     LIT + "    lights: []\n",
     9, "views[0].lights", "expected at least one light"),
    ("view_lights_without_spec_lights",
     CAM + "views:\n  - camera: cam\n    look_at: [{eye: [0, -2, 1], target: [0, 0, 0]}]\n"
     "    lights: [light0]\n",
     6, "views[0].lights", "the spec defines no lights"),
]


@pytest.mark.parametrize("text,line,field,fragment", [c[1:] for c in CASES],
                         ids=[c[0] for c in CASES])
def test_malformed_spec(tmp_path, text, line, field, fragment):
    with pytest.raises(SpecError) as info:
        parse_spec(text, file="scene.yaml", base_dir=tmp_path)
    err = info.value
    assert (err.file, err.line, err.field) == ("scene.yaml", line, field), str(err)
    assert fragment in err.message, str(err)
    prefix = f"scene.yaml:{line}: " + (f"{field}: " if field else "")
    assert str(err).startswith(prefix)


def test_table_is_large_enough():
    assert len(CASES) >= 20 and len({c[0] for c in CASES}) == len(CASES)


def test_impossible_camera_reported_at_its_field():
    import scenegen.geometry.camera  # noqa: F401
    text = textwrap.dedent("""\
        cameras:
          cam:
            model: opencv
            size: [640, 480]
            fx: 100
            dist: [-3, 0, 0, 0, 5]
        """)
    with pytest.raises(SpecError) as info:
        parse_spec(text, file="scene.yaml")
    assert (info.value.line, info.value.field) == (6, "cameras.cam.dist")
    assert "impossible camera" in info.value.message


def test_load_spec_names_the_file_as_given(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("render:\n  spp: many\n")
    with pytest.raises(SpecError) as info:
        load_spec(p)
    assert str(info.value) == (f"{p}:2: render.spp: expected an integer (samples per pixel), "
                               "got 'many'")
