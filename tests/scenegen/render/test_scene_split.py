"""The scene in three parts (issue 26): a description that travels without Mitsuba, a device
scene built from it, and casts whose result depends on their arguments alone (no current time
left over from an earlier call), with the rolling-shutter row tables cached by content."""
import dataclasses
import pickle

import numpy as np
import pytest

from scenegen.pipeline.view import rolling_rows, view_truth
from scenegen.render import load_scene
from scenegen.render.description import describe
from scenegen.spec import parse_spec, resolve_views

pytestmark = pytest.mark.render

SPEC = """
name: split
render: {spp: 1, max_depth: 2}
sequence: {fps: 10, frames: 3, flow_steps: [1]}
objects:
  - name: floor
    shape: {type: plane, size: [4, 4]}
    material: {type: diffuse, texture: {type: noise, params: {octaves: 2}}}
  - name: ball
    shape: {type: sphere, radius: 0.25}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [-0.4, 0.1, 0.25]}
        - {time_s: 0.2, translation: [0.4, -0.1, 0.35]}
  - name: crate
    shape: {type: box, size: [0.3, 0.2, 0.25]}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [0.35, 0.3, 0.125]}
        - {time_s: 0.2, translation: [-0.2, 0.25, 0.2], rotation_deg: [0, 0, 60]}
lights: [{type: constant, radiance: 1}]
cameras: {cam: {size: [40, 30], fx: 35, shutter: {rolling_readout_s: 0.03}}}
views:
  - camera: cam
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0.2, -1.8, 1.3], target: [0, 0, 0.1]}
        - {time_s: 0.2, eye: [-0.2, -1.7, 1.4], target: [0, 0.05, 0.1]}
"""


def _spec(tmp_path):
    return parse_spec(SPEC, file=str(tmp_path / "split.yaml"), base_dir=str(tmp_path))


def test_description_pickles_without_mitsuba_and_hashes_its_content(tmp_path):
    spec = _spec(tmp_path)
    d = describe(spec, spp=4, sampler="ldsampler", max_depth=2)
    blob = pickle.dumps(d)
    assert b"mitsuba" not in blob and b"drjit" not in blob  # no Mitsuba object inside
    back = pickle.loads(blob)
    assert back.content_hash == d.content_hash
    for name, mesh in d.meshes_world.items():
        np.testing.assert_array_equal(back.meshes_world[name].vertices, mesh.vertices)
    assert describe(_spec(tmp_path), spp=4, sampler="ldsampler", max_depth=2).content_hash == d.content_hash
    assert describe(spec, spp=8, sampler="ldsampler", max_depth=2).content_hash != d.content_hash
    with pytest.raises(dataclasses.FrozenInstanceError):
        d.spp = 8


def test_a_cast_depends_on_its_time_not_on_the_previous_cast(tmp_path):
    """Truth at frame 1's time is the same bytes whether the scene was cast at frame 2 before or
    not, and equals a fresh scene's; a cast without a time is frame 0's."""
    spec = _spec(tmp_path)
    views = resolve_views(spec)
    fresh = load_scene(spec, variant="llvm_ad_rgb")
    first = view_truth(fresh, views[1], as_stored=True)
    used = load_scene(spec, variant="llvm_ad_rgb")
    view_truth(used, views[2], as_stored=True)
    again = view_truth(used, views[1], as_stored=True)
    for k in first:
        np.testing.assert_array_equal(again[k], first[k], err_msg=k)
    cam, pose = used.cameras["cam"], views[0].cam_from_world
    at_rest = used.truth(cam, pose)
    at_zero = fresh.truth(cam, pose, time_s=views[0].time_s)
    np.testing.assert_array_equal(at_rest["range"], at_zero["range"])
    assert not np.array_equal(at_rest["object_id"], used.truth(cam, pose, time_s=views[2].time_s)["object_id"])


def test_row_tables_are_keyed_by_content_not_by_view_name(tmp_path):
    spec = _spec(tmp_path)
    views = resolve_views(spec)
    built = load_scene(spec, variant="llvm_ad_rgb")
    rows = rolling_rows(built, views[1])
    assert rows is not None and rows.objects
    assert rolling_rows(built, dataclasses.replace(views[1], name="renamed")) is rows
    assert rolling_rows(built, views[2]) is not rows
