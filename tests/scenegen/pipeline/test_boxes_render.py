"""Bounding boxes of a rendered scene (``truth: {boxes: true}``) against independent computations:
numpy on the stored object-id map (visible boxes), trimesh bounds of the stored world meshes taken
into the object frame (3D boxes), OpenCV's projectPoints of the stored meshes' vertices and of the
8 corners, with the camera's distortion (amodal boxes); a sequence's frames against the poses of
sequence/objects.json. Tiny renders: 32x24 px, 4 spp."""
import json
import shutil

import cv2
import numpy as np
import pytest

from scenegen.dataset import Dataset, DatasetError, verify
from scenegen.dataset.layout import boxes_path
from scenegen.geometry.pose import Rigid3
from scenegen.pipeline.run import render_spec

pytestmark = pytest.mark.render

SCENE = """
name: boxes
render: {{spp: 4, max_depth: 2}}
{truth}
lights: [{{type: constant, radiance: 1}}]
cameras:
  cam: {{model: opencv, size: [32, 24], fx: 26, fy: 26, dist: [0.08, -0.05, 0.001, -0.002]}}
views:
{views}
objects:
  - name: ground
    shape: {{type: plane, size: [1.2, 1.2]}}
  - name: crate
    shape: {{type: box, size: [0.3, 0.2, 0.25]}}
    transform: {{translation: [0.05, 0.0, 0.2], rotation_deg: [10, -20, 35], scale: [1.0, 1.5, 0.8]}}
{crate_motion}
  - name: ball
    shape: {{type: sphere, radius: 0.12}}
    transform: {{translation: [-0.3, 0.2, 0.12]}}
  - name: post
    shape: {{type: cylinder, radius: 0.05, height: 0.6}}
    transform: {{translation: [0.62, 0.1, 0.3]}}
"""
STILL_VIEWS = """  - camera: cam
    look_at: [{eye: [0.3, -1.6, 1.0], target: [0.1, 0.0, 0.15]}, {eye: [-0.8, -1.2, 0.7], target: [0.0, 0.1, 0.2]}]"""
SEQUENCE_VIEWS = """  - camera: cam
    trajectory:
      keyframes: [{time_s: 0, eye: [0.3, -1.6, 1.0], target: [0.1, 0.0, 0.15]}]"""
CRATE_MOTION = """    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [0.05, 0.0, 0.2], rotation_deg: [10, -20, 35]}
        - {time_s: 0.1, translation: [-0.1, 0.1, 0.25], rotation_deg: [10, -20, 60]}"""


def _render(tmp_path, name, *, truth="truth: {boxes: true}", views=STILL_VIEWS, crate_motion="", head=""):
    spec = tmp_path / f"{name}.yaml"
    text = head + SCENE.format(truth=truth, views=views, crate_motion=crate_motion)
    if crate_motion:  # the keyframes place the crate; its transform keeps only the scale
        text = text.replace("translation: [0.05, 0.0, 0.2], rotation_deg: [10, -20, 35], scale:", "scale:")
    spec.write_text(text)
    render_spec(spec, tmp_path / name, progress=False)
    return Dataset(tmp_path / name)


@pytest.fixture(scope="module")
def still(tmp_path_factory):
    return _render(tmp_path_factory.mktemp("boxes"), "still")


def _object_from_world_vertices(ds, name, world_from_object):
    """The stored world mesh (float32 PLY) in the object frame, as trimesh sees it."""
    mesh = ds.mesh(name).copy()
    mesh.apply_transform(world_from_object.inverse().matrix)
    return mesh


def _mesh_pose(ds):
    """name -> the pose the stored world mesh was placed at (the spec's ``transform``)."""
    poses = {o["name"]: o["transform"]["world_from_object"] for o in ds.spec["objects"]}
    return lambda name: Rigid3.from_dict(poses[name])


def _check_view(ds, view):
    world_meshes = _mesh_pose(ds)
    boxes = ds.boxes(view)
    camera, cam_from_world = ds.camera(view)
    ids = ds.object_ids(view)
    K, dist = camera.to_opencv()
    assert boxes.image_size == (32, 24) and boxes.cam_from_world.allclose(cam_from_world)
    assert [o.name for o in boxes.objects] == [o["name"] for o in ds.objects]
    seen = projected = 0
    for o in boxes.objects:
        # (a) visible: numpy on the ids map
        rows, cols = np.nonzero(ids == o.object_id)
        if rows.size == 0:
            assert o.visible is None
        else:
            seen += 1
            assert o.visible.pixel_count == rows.size
            assert o.visible.box_xyxy_px == (cols.min(), rows.min(), cols.max(), rows.max())
        # (c) 3D: trimesh bounds of the stored mesh in the object frame; corners in every frame
        b = o.box3d
        assert b.cam_from_object.allclose(cam_from_world @ b.world_from_object, atol=1e-12)
        mesh = _object_from_world_vertices(ds, o.name, world_meshes(o.name))  # the object frame
        assert np.allclose(mesh.bounds, [b.corners_object_m.min(0), b.corners_object_m.max(0)], atol=2e-6)
        assert np.allclose(b.corners_world_m, b.world_from_object.apply(b.corners_object_m), atol=1e-12)
        assert np.allclose(b.corners_cam_m, cam_from_world.apply(b.corners_world_m), atol=1e-12)
        # (b) amodal: OpenCV projectPoints of the mesh's vertices (world frame) with the distortion
        rvec = cv2.Rodrigues(cam_from_world.R)[0]
        world = b.world_from_object.apply(mesh.vertices)
        in_front = (cam_from_world.apply(world)[:, 2] > 0).all()
        if in_front and not o.amodal.vertices_projected < o.amodal.vertices_total:
            projected += 1
            uv = cv2.projectPoints(world, rvec, cam_from_world.t, K, dist)[0].reshape(-1, 2)
            assert np.allclose(o.amodal.box_xyxy_px, [*uv.min(0), *uv.max(0)], atol=2e-4), o.name
            lo, hi = uv.min(0), uv.max(0)
            inside = lo.min() >= -0.5 and hi[0] <= 31.5 and hi[1] <= 23.5
            assert o.amodal.clipped == (not inside)
            w = max(0.0, min(hi[0], 31.5) - max(lo[0], -0.5))
            h = max(0.0, min(hi[1], 23.5) - max(lo[1], -0.5))
            assert o.amodal.truncation == pytest.approx(1 - w * h / np.prod(hi - lo), abs=1e-4)
            # the visible pixels lie inside the amodal box (a pixel centre sees the object)
            if o.visible is not None:
                u0, v0, u1, v1 = o.visible.box_xyxy_px
                a = o.amodal.box_xyxy_px
                assert a[0] - 0.5 <= u0 and u1 <= a[2] + 0.5 and a[1] - 0.5 <= v0 and v1 <= a[3] + 0.5
            # the corners in the camera frame project (OpenCV) where the camera model puts them
            cuv = cv2.projectPoints(b.corners_world_m, rvec, cam_from_world.t, K, dist)[0].reshape(-1, 2)
            assert np.allclose(camera.project(b.corners_cam_m), cuv, atol=1e-6)
    assert projected == len(boxes.objects)  # every object in front of the camera: all compared
    return boxes, seen


def test_still_views_boxes_against_independent_computations(still):
    assert verify(still.root).ok
    for view in still.views:
        assert still.has(boxes_path(view))
        boxes, seen = _check_view(still, view)
        assert seen >= 3
    crate = still.boxes(still.views[0]).by_name("crate").box3d
    assert np.allclose(crate.size_m, [0.3, 0.3, 0.2], atol=1e-12)  # the box's size times the scale


def test_no_boxes_without_the_option(tmp_path):
    ds = _render(tmp_path, "plain", truth="", views=STILL_VIEWS.split(", {eye: [-0.8")[0] + "]")
    assert ds.boxes(ds.views[0]) is None
    assert not any(p.endswith("_boxes.json") for p in ds.manifest["files"])
    assert "truth" not in ds.spec  # the resolved spec (and its hash) as before the option existed


def test_sequence_frames_have_boxes_at_their_time(tmp_path):
    head = "sequence: {fps: 10, frames: 2, flow_steps: [1]}\n"
    ds = _render(tmp_path, "seq", views=SEQUENCE_VIEWS, crate_motion=CRATE_MOTION, head=head)
    assert verify(ds.root).ok and len(ds.views) == 2
    crate = []
    for frame, view in enumerate(ds.views):
        poses = ds.sequence.object_poses(frame)
        boxes, _ = _check_view(ds, view)
        for o in boxes.objects:
            assert o.box3d.world_from_object.allclose(poses[o.name][0], atol=1e-12) and o.present
        crate.append(boxes.by_name("crate"))
    assert not crate[0].box3d.world_from_object.allclose(crate[1].box3d.world_from_object)
    assert np.array_equal(crate[0].box3d.corners_object_m, crate[1].box3d.corners_object_m)


def test_damaged_boxes_file_names_the_file_and_field(still, tmp_path):
    damaged = tmp_path / "damaged"
    shutil.copytree(still.root, damaged)
    view = still.views[0]
    path = damaged / boxes_path(view)
    doc = json.loads(path.read_text())
    doc["objects"][1]["box3d"]["size_m"] = [0.3, 0.3]
    path.write_text(json.dumps(doc))
    with pytest.raises(DatasetError, match=rf"{view}_boxes\.json: unreadable boxes of view '{view}': "
                                           r".*objects\[1\]\.box3d\.size_m: expected"):
        Dataset(damaged).boxes(view)
