"""Bounding boxes (scenegen/crossview/boxes.py, scenegen/dataset/boxes.py) against independent
computations: numpy per object on an id map, OpenCV's projectPoints with distortion, the closed
form of a box's area outside the image, and the stored document read back."""
import cv2
import numpy as np
import pytest

from scenegen.crossview.boxes import amodal_box, box3d, object_boxes, visible_boxes
from scenegen.dataset.boxes import ViewBoxes, boxes_document, decode_boxes
from scenegen.dataset.codecs import encode_json
from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import BOX_CORNER_SIGNS, coco_box_of_extent, coco_box_of_pixels
from scenegen.geometry.pose import Rigid3, look_at

CAM = Camera.from_opencv(np.array([[30.0, 0, 15.5], [0, 31.0, 11.5], [0, 0, 1]]),
                         np.array([0.08, -0.05, 0.001, -0.002, 0.0]), (32, 24))


def test_visible_boxes_equal_numpy_per_object():
    rng = np.random.default_rng(3)
    ids = np.zeros((24, 32), np.uint32)
    for k, (v0, u0, h, w) in enumerate([(2, 3, 5, 7), (10, 0, 14, 9), (0, 20, 3, 12)], start=1):
        ids[v0:v0 + h, u0:u0 + w] = k
    ids[rng.random(ids.shape) < 0.1] = 7  # scattered pixels of one more object
    boxes = visible_boxes(ids)
    assert sorted(boxes) == sorted(int(k) for k in np.unique(ids) if k)
    for k, b in boxes.items():
        rows, cols = np.where(ids == k)
        assert b.pixel_count == rows.size
        assert b.box_xyxy_px == (cols.min(), rows.min(), cols.max(), rows.max())
        # COCO: the covered pixel squares, edges at integers (pixel u spans [u, u + 1])
        x, y, w, h = b.coco_xywh
        assert (x, y, x + w, y + h) == (cols.min(), rows.min(), cols.max() + 1, rows.max() + 1)
    assert visible_boxes(np.zeros((3, 4), np.uint32)) == {}


def test_amodal_box_equals_opencv_projection():
    rng = np.random.default_rng(5)
    pts = rng.uniform([-0.3, -0.2, 1.5], [0.3, 0.2, 2.5], (200, 3))  # all in front, inside the image
    a = amodal_box(CAM, pts)
    K, dist = CAM.to_opencv()
    uv = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), K, dist)[0].reshape(-1, 2)
    assert np.allclose(a.box_xyxy_px, [*uv.min(0), *uv.max(0)], atol=1e-9)
    assert not a.clipped and a.truncation == 0.0 and a.vertices_projected == a.vertices_total == 200
    assert np.allclose(a.coco_xywh, [uv[:, 0].min() + 0.5, uv[:, 1].min() + 0.5, *np.ptp(uv, axis=0)])


def test_truncation_is_the_area_outside_the_image():
    pinhole = Camera.from_opencv(np.array([[20.0, 0, 15.5], [0, 20.0, 11.5], [0, 0, 1]]), np.zeros(5), (32, 24))
    # a fronto-parallel square at z = 1 projecting to [u0, u1] x [v0, v1]: u = 20 x + 15.5
    u0, u1, v0, v1 = 20.0, 40.0, 5.0, 15.0
    pts = np.array([[(u - 15.5) / 20, (v - 11.5) / 20, 1.0] for u in (u0, u1) for v in (v0, v1)])
    a = amodal_box(pinhole, pts)
    assert np.allclose(a.box_xyxy_px, [u0, v0, u1, v1])
    inside = (31.5 - u0) * (v1 - v0)  # the image ends at W - 0.5 = 31.5
    assert a.clipped and a.truncation == pytest.approx(1 - inside / ((u1 - u0) * (v1 - v0)), abs=1e-12)
    behind = amodal_box(pinhole, np.vstack([pts, [[0.0, 0.0, -1.0]]]))  # a vertex behind the camera
    assert behind.clipped and behind.truncation is None and behind.vertices_projected == 4
    assert amodal_box(pinhole, -pts).box_xyxy_px is None


def test_box3d_corners_in_every_frame():
    rng = np.random.default_rng(11)
    verts = rng.normal(size=(50, 3)) * [0.3, 0.1, 0.2] + [0.05, 0, 0.1]
    world_from_object = Rigid3.from_rotvec([0.3, -0.2, 1.1], [0.5, -0.4, 0.2])
    cam_from_world = look_at([1.5, -2.0, 1.0], [0.0, 0.0, 0.0])
    b = box3d(verts, world_from_object, cam_from_world)
    assert np.allclose(b.corners_object_m.min(0), verts.min(0)) and np.allclose(b.corners_object_m.max(0), verts.max(0))
    assert np.allclose(b.size_m, np.ptp(verts, axis=0)) and np.allclose(b.center_object_m, (verts.min(0) + verts.max(0)) / 2)
    assert np.array_equal(np.sign(b.corners_object_m - b.center_object_m), BOX_CORNER_SIGNS)
    T_world = world_from_object.matrix
    hom = np.c_[b.corners_object_m, np.ones(8)]
    assert np.allclose(b.corners_world_m, (hom @ T_world.T)[:, :3], atol=1e-14)
    assert np.allclose(b.corners_cam_m, (hom @ (cam_from_world.matrix @ T_world).T)[:, :3], atol=1e-14)


def test_coco_conversions():
    assert coco_box_of_pixels([3, 4, 3, 4]) == [3.0, 4.0, 1.0, 1.0]  # one pixel: a unit square
    assert coco_box_of_extent([-0.5, -0.5, 31.5, 23.5]) == [0.0, 0.0, 32.0, 24.0]  # the whole image


def _view_boxes():
    ids = np.zeros((24, 32), np.uint32)
    ids[5:9, 10:20] = 1
    vis = visible_boxes(ids)
    pose = look_at([0.0, -2.0, 0.5], [0.0, 0.0, 0.0])
    cube = BOX_CORNER_SIGNS * 0.1
    objs = (object_boxes("a", 1, 1, present=True, vertices_object=cube, world_from_object=Rigid3.identity(),
                         camera=CAM, cam_from_world=pose, visible=vis),
            object_boxes("b", 2, 1, present=False, vertices_object=cube * 2,
                         world_from_object=Rigid3.from_rotvec([0, 0, 1.0], [0.3, 0, 0]), camera=CAM,
                         cam_from_world=pose, visible=vis))
    return ViewBoxes("v0", (32, 24), pose, objs)


def test_document_round_trip():
    vb = _view_boxes()
    doc = boxes_document(vb)
    back = decode_boxes(__import__("json").loads(encode_json(doc)), "x.json")
    assert boxes_document(back) == doc and encode_json(boxes_document(back)) == encode_json(doc)
    a, b = back.by_name("a"), back.by_name("b")
    assert a.visible.pixel_count == 40 and a.visible.box_xyxy_px == (10, 5, 19, 8)
    assert b.visible is None and b.amodal is None and not b.present
    assert np.allclose(b.box3d.size_m, 0.4)


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.update(format="x"), "x.json: expected a scenegen.boxes/1 document"),
    (lambda d: d["objects"][0]["box3d"].update(size_m=[1, 2]), "objects[0].box3d.size_m: expected"),
    (lambda d: d["objects"][0]["amodal"].update(truncation=2), "objects[0].amodal.truncation"),
    (lambda d: d["objects"][0]["visible"].update(pixel_count=-1), "objects[0].visible.pixel_count"),
    (lambda d: d["objects"][1]["box3d"]["cam_from_object"].update(t=[0, "a", 0]), "objects[1].box3d.cam_from_object"),
])
def test_bad_document_names_the_field(edit, message):
    doc = boxes_document(_view_boxes())
    edit(doc)
    with pytest.raises(ValueError, match=__import__("re").escape(message)):
        decode_boxes(doc, "x.json")
