"""The sequence parts of a spec: the clock, trajectories of cameras, rigs and objects, parents,
joints and visible intervals; views per frame; bad input as file:line: field errors; and specs
without a sequence keep their canonical form."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen.errors import SpecError
from scenegen.spec import parse_spec, resolve_views, spec_to_dict
from scenegen.spec.timeline import Timeline

CAM = "cameras:\n  cam: {size: [64, 48], fx: 50}\n"
SEQ = "sequence: {fps: 10, frames: 4}\n"
TRAJ = ("    trajectory:\n      keyframes:\n        - {time_s: 0, eye: [0, -2, 1], target: [0, 0, 0]}\n"
        "        - {time_s: 0.3, eye: [0.5, -2, 1], target: [0, 0, 0]}\n")
VIEWS = "views:\n  - camera: cam\n" + TRAJ


def parse(text, tmp_path):
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


def test_views_are_frames_at_the_clock_times(tmp_path):
    s = parse(CAM + SEQ + VIEWS, tmp_path)
    views = resolve_views(s)
    assert [v.name for v in views] == [f"cam_{k:04d}" for k in range(4)]
    assert [v.time_s for v in views] == pytest.approx([0.0, 0.1, 0.2, 0.3])
    assert np.allclose(views[-1].cam_from_world.inverse().t, [0.5, -2, 1])
    assert spec_to_dict(s)["views"][2]["time_s"] == pytest.approx(0.2)


def test_explicit_timestamps_and_a_rig_moving_as_one(tmp_path):
    text = (CAM + "sequence: {timestamps_s: [0, 0.05, 0.3]}\nrigs:\n  st: {type: stereo, left: cam, "
            "right: cam, baseline_m: 0.1}\nviews:\n  - rig: st\n" + TRAJ.replace("eye", "eye"))
    views = resolve_views(parse(text, tmp_path))
    assert [v.time_s for v in views] == [0, 0, 0.05, 0.05, 0.3, 0.3]
    for left, right in zip(views[::2], views[1::2]):
        rel = right.cam_from_world @ left.cam_from_world.inverse()
        assert np.allclose(rel.t, [-0.1, 0, 0]) and np.allclose(rel.R, np.eye(3))


def test_a_shutter_moves_the_camera_along_its_trajectory_within_the_frame(tmp_path):
    from scenegen.geometry.optics import PathMotion, cam_from_world_at

    cam = "cameras:\n  cam: {size: [64, 48], fx: 50, shutter: {exposure_s: 0.01}}\n"
    spec = parse(cam + SEQ + VIEWS, tmp_path)
    v = resolve_views(spec)[1]
    assert isinstance(v.motion, PathMotion)
    traj = spec.view_sets[0].placement.trajectory.trajectory()
    for tau in (-0.004, 0.003):
        assert cam_from_world_at(v.cam_from_world, v.motion, tau).allclose(traj.pose(0.1 + tau).inverse(), 1e-12)
    assert resolve_views(parse(CAM + SEQ + VIEWS, tmp_path))[1].motion is None  # no shutter: no motion


OBJECTS = """objects:
  - name: base
    shape: {type: box, size: [0.2, 0.2, 0.1]}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0, translation: [0, 0, 0.05]}
        - {time_s: 0.3, translation: [0.3, 0, 0.05], rotation_deg: [0, 0, 90]}
  - name: lid
    shape: {type: box, size: [0.2, 0.2, 0.02]}
    parent: base
    transform: {translation: [0, 0, 0.06]}
    joint: {type: revolute, axis: [1, 0, 0], origin: [0, 0.1, 0.05], keyframes: [{time_s: 0, angle_deg: 0}, {time_s: 0.3, angle_deg: 90}]}
  - name: flash
    shape: {type: box, size: [0.05, 0.05, 0.05]}
    visible_s: [0.1, 0.2]
"""


def test_a_tree_of_parts_with_a_joint_and_a_visible_interval(tmp_path):
    s = parse(CAM + SEQ + OBJECTS + VIEWS, tmp_path)
    tl = Timeline(s)
    st = tl.states(0.3)
    base, lid = st["base"].world_from_object, st["lid"].world_from_object
    assert np.allclose(base.t, [0.3, 0, 0.05])
    rel = base.inverse() @ lid  # parent_from_lid: 90 degrees about x through the hinge
    hinge = np.array([0.0, 0.1, 0.05])
    assert np.allclose(rel.apply(hinge - [0, 0, 0.06]) , hinge)
    assert np.allclose(rel.R @ [0, 1, 0], [0, 0, 1])
    assert s.objects[1].transform.world_from_object.allclose(tl.states(0.0)["lid"].world_from_object)
    assert [tl.states(t)["flash"].present for t in (0.0, 0.1, 0.2, 0.3)] == [False, True, True, False]
    assert tl.animated == ("base", "lid", "flash")


ERRORS = [
    ("trajectory_without_sequence", CAM + VIEWS, 6, "views[0].trajectory", "needs a top-level 'sequence:'"),
    ("static_view_set_in_sequence", CAM + SEQ + "views:\n  - camera: cam\n    look_at: [{eye: [0, -2, 1], target: [0, 0, 0]}]\n",
     6, "views[0].look_at", "every view set follows a 'trajectory'"),
    ("keyframes_not_increasing", CAM + SEQ + VIEWS.replace("time_s: 0.3", "time_s: 0"), 9,
     "views[0].trajectory.keyframes[1].time_s", "strictly increasing"),
    ("fps_without_frames", "sequence: {fps: 10}\n", 1, "sequence.frames", "missing required key 'frames'"),
    ("timestamps_not_increasing", "sequence: {timestamps_s: [0, 0.2, 0.1]}\n", 1,
     "sequence.timestamps_s[2]", "strictly increasing"),
    ("query_frame_beyond_clock", "sequence: {fps: 10, frames: 4, tracks: {query_frames: [0, 4]}}\n", 1,
     "sequence.tracks.query_frames[1]", "below 4"),
    ("object_trajectory_without_sequence",
     "objects:\n  - name: a\n    shape: box\n    trajectory: {keyframes: [{time_s: 0}]}\n", 4,
     "objects[0].trajectory", "needs a top-level 'sequence:'"),
    ("unknown_parent", SEQ + "objects:\n  - {name: a, shape: box, parent: b}\n", 3, "objects[0].parent",
     "a parent must come earlier"),
    ("motion_and_trajectory", SEQ + "objects:\n  - name: a\n    shape: box\n    motion: {linear_velocity_mps: [1, 0, 0]}\n"
     "    trajectory: {keyframes: [{time_s: 0}]}\n", 5, "objects[0].motion", "cannot be combined"),
    ("transform_with_trajectory", SEQ + "objects:\n  - name: a\n    shape: box\n    transform: {translation: [1, 0, 0]}\n"
     "    trajectory: {keyframes: [{time_s: 0}]}\n", 5, "objects[0].transform", "may give only 'scale'"),
    ("visible_reversed", SEQ + "objects:\n  - {name: a, shape: box, visible_s: [0.3, 0.1]}\n", 3,
     "objects[0].visible_s", "appears <= leaves"),
    ("sphere_cannot_leave", SEQ + "objects:\n  - {name: a, shape: sphere, visible_s: [0, 0.1]}\n", 3,
     "objects[0].visible_s", "analytic sphere cannot leave"),
    ("joint_zero_axis", SEQ + "objects:\n  - name: a\n    shape: box\n    joint: {type: revolute, axis: [0, 0, 0], "
     "keyframes: [{time_s: 0, angle_deg: 0}]}\n", 5, "objects[0].joint.axis", "non-zero axis"),
    ("joint_key_of_other_type", SEQ + "objects:\n  - name: a\n    shape: box\n    joint: {type: prismatic, axis: [0, 0, 1], "
     "keyframes: [{time_s: 0, angle_deg: 0}]}\n", 5, "objects[0].joint.keyframes[0].angle_deg", "unknown key"),
    ("crossview_flow_with_moving_objects", CAM + SEQ + "objects:\n  - {name: a, shape: box, visible_s: [0, 1]}\n"
     + VIEWS + "crossview: {}\n", 12, "crossview", "set flow: false"),
    ("crossview_pairs_across_time", CAM + SEQ + "objects:\n  - {name: a, shape: box, visible_s: [0, 1]}\n"
     + VIEWS + "crossview: {flow: false}\n", 12, "crossview", "relates frames of different times"),
    ("crossview_explicit_pair_across_time", CAM + SEQ + "objects:\n  - {name: a, shape: box, visible_s: [0, 1]}\n"
     + VIEWS + "crossview:\n  flow: false\n  pairs: [[cam_0000, cam_0001]]\n", 14, "crossview.pairs[0]",
     "are at 0 s and 0.1 s"),
]


@pytest.mark.parametrize("text,line,field,fragment", [c[1:] for c in ERRORS], ids=[c[0] for c in ERRORS])
def test_bad_sequence_input_names_file_line_and_field(tmp_path, text, line, field, fragment):
    with pytest.raises(SpecError) as info:
        parse(text, tmp_path)
    err = info.value
    assert (err.file, err.line, err.field) == ("scene.yaml", line, field), str(err)
    assert fragment in err.message, str(err)


def test_a_static_spec_has_no_time_in_its_resolved_form(tmp_path):
    d = spec_to_dict(parse(CAM + "views:\n  - camera: cam\n    look_at: [{eye: [0, -2, 1], target: [0, 0, 0]}]\n"
                           "objects:\n  - {name: a, shape: box}\n", tmp_path))
    assert "sequence" not in d and "time_s" not in d["views"][0] and "animation" not in d["objects"][0]


def test_variants_of_a_sequence_jitter_the_keyframes(tmp_path):
    from scenegen.spec.variants import derive_variant
    s = parse(CAM + SEQ + VIEWS + "variation: {seed: 4, views: {translation_m: 0.05, rotation_deg: 2}}\n", tmp_path)
    v = derive_variant(s, 1)
    a, b = resolve_views(s), resolve_views(v)
    assert [x.time_s for x in b] == [x.time_s for x in a]
    d = [np.linalg.norm(x.cam_from_world.inverse().t - y.cam_from_world.inverse().t) for x, y in zip(a, b)]
    assert 0 < max(d) <= 0.05 * 3 ** 0.5 + 1e-9


def test_a_moving_object_cannot_have_its_placement_varied(tmp_path):
    text = (SEQ + "objects:\n  - {name: a, shape: box, visible_s: [0, 1]}\n"
            "variation: {objects: {a: {position: {min: [0, 0, 0], max: [1, 1, 0]}}}}\n")
    with pytest.raises(SpecError) as info:
        parse(text, tmp_path)
    assert info.value.line == 4 and "moves over the sequence" in info.value.message


def test_a_child_exists_only_while_its_parent_does(tmp_path):
    text = SEQ + ("objects:\n  - {name: a, shape: box, visible_s: [0.1, 0.2]}\n"
                  "  - {name: b, shape: box, parent: a, transform: {translation: [0, 0, 1]}}\n")
    tl = Timeline(parse(text, tmp_path))
    assert [tl.states(t)["b"].present for t in (0.0, 0.1, 0.2, 0.3)] == [False, True, True, False]
    assert np.allclose(tl.states(0.0)["b"].world_from_object.t, [0, 0, 1])


def test_every_object_is_a_trajectory_on_the_clock(tmp_path):
    """Timeline.object_trajectory (parents composed) and object_moves_at_times (one time per ray,
    vectorised) give the per-time states' poses, velocities and presence."""
    s = parse(CAM + SEQ + OBJECTS + VIEWS, tmp_path)
    tl = Timeline(s)
    times = np.concatenate([np.linspace(-0.05, 0.35, 41), [0.1, 0.2, 0.3]])
    moves = tl.object_moves_at_times(times)
    assert set(moves) == {o.object_id for o in s.objects}
    for k, t in enumerate(times):
        st = tl.states(float(t))
        for o in s.objects:
            R, tr, present = moves[o.object_id]
            want = st[o.name]
            assert np.abs(R[k] - want.world_from_object.R).max() < 1e-15
            assert np.abs(tr[k] - want.world_from_object.t).max() < 1e-15 and present[k] == want.present
            traj = tl.object_trajectory(o.name)
            assert np.abs(traj.velocity_at(t)[0] - want.motion.linear_velocity_mps).max() < 1e-12
            assert np.abs(traj.angular_velocity_at(t)[0] - want.motion.angular_velocity_rad_s).max() < 1e-12


def test_a_still_specs_moving_object_is_a_trajectory_from_mid_exposure(tmp_path):
    from scenegen.spec.timeline import poses_within_frame

    text = (CAM + "objects:\n  - {name: m, shape: box, transform: {translation: [0, 0, 1]},\n"
            "     motion: {linear_velocity_mps: [1, 0, 0], angular_velocity_deg_s: [0, 0, 90]}}\n"
            "  - {name: still, shape: box}\n"
            "views:\n  - camera: cam\n    look_at: [{eye: [0, -2, 1], target: [0, 0, 0]}]\n")
    tl = Timeline(parse(text, tmp_path))
    taus = np.linspace(-0.01, 0.01, 9)
    moves = tl.object_moves_at_times(taus)
    want = poses_within_frame(tl, None, taus)
    assert set(moves) == set(want) == {tl.objects[0].object_id}
    for a, b in zip(moves[tl.objects[0].object_id], want[tl.objects[0].object_id]):
        assert np.abs(np.asarray(a, float) - np.asarray(b, float)).max() < 1e-14


def test_a_single_frame_sequence_keeps_no_default_flow_step_and_round_trips():
    from scenegen.spec import parse_spec, to_yaml

    text = ("cameras:\n  c: {size: [32, 24], fx: 30}\nobjects:\n  - {name: b, shape: sphere}\nviews:\n"
            "  - camera: c\n    trajectory: {keyframes: [{time_s: 0, eye: [0, -3, 1], target: [0, 0, 0]}]}\n"
            "sequence: {fps: 10, frames: 1}\n")
    spec = parse_spec(text, file="one.yaml")
    assert spec.sequence.flow_steps == ()
    assert parse_spec(to_yaml(spec), file="again.yaml").sequence == spec.sequence
