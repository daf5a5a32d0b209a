"""The object truth document (scenegen.dataset.objects): encode / decode round trip and a damaged
document's error naming the field."""
import json

import numpy as np
import pytest

from scenegen.dataset.objects import (KeypointTruth, ModelInfo, ObjectTruth, ViewObjects, decode_objects,
                                      objects_arrays, objects_document)
from scenegen.geometry.pose import Rigid3


def _view() -> ViewObjects:
    pose = Rigid3(np.eye(3), np.array([0.0, 0.1, 1.0]))
    kp = (KeypointTruth("top", np.array([0.0, 0.0, 0.05]), np.array([3.5, 2.25]), 0.95, "visible"),
          KeypointTruth("far", np.array([0.5, 0.0, 0.0]), np.array([np.nan, np.nan]), float("nan"), "out_of_image"))
    obj = ObjectTruth("crate_1", 2, 2, "crate", 1, None, True, pose, pose, pose, 12, 9, 0.75, (1, 1, 4, 3),
                      (1, 2, 4, 3), kp)
    model = ModelInfo("crate", 1, 0.17, (np.diag([-1.0, -1.0, 1.0, 1.0]),), ({"axis": [0.0, 0.0, 1.0],
                      "offset": [0.0, 0.0, 0.0]},), ("top", "far"), (("top", "far"),))
    mask = np.zeros((1, 5, 11), bool)
    mask[0, 1:4, 1:5] = True
    return ViewObjects("v", (11, 5), pose, (model,), (obj,), mask)


def _roundtrip(doc, arrays):
    return decode_objects(json.loads(json.dumps(doc)), arrays, "truth/v_objects.json")


def test_round_trip():
    v = _view()
    back = _roundtrip(objects_document(v), objects_arrays(v))
    np.testing.assert_array_equal(back.mask_full, v.mask_full)
    o = back.objects[0]
    assert (o.px_count_all, o.visib_fract, o.box_obj_xyxy_px, o.keypoints[1].state) == (12, 0.75, (1, 1, 4, 3),
                                                                                      "out_of_image")
    assert np.isnan(o.keypoints[1].uv_px).all() and o.keypoints[0].uv_px.tolist() == [3.5, 2.25]
    np.testing.assert_array_equal(back.models[0].symmetries_discrete[0], v.models[0].symmetries_discrete[0])


@pytest.mark.parametrize("damage, field", [
    (lambda d: d.update(format="x"), "scenegen.objects/1"),
    (lambda d: d["objects"][0].update(visib_fract=1.5), "objects[0]"),
    (lambda d: d["objects"][0]["cam_from_object"].update(R=[[1, 0], [0, 1]]), "objects[0].cam_from_object"),
    (lambda d: d["objects"][0]["keypoints"][0].update(state="hidden"), "objects[0].keypoints[0]"),
    (lambda d: d["objects"][0].update(box_obj_xyxy_px=[1, 2, 3]), "objects[0].box_obj_xyxy_px"),
    (lambda d: d["models"][0].update(symmetries_discrete=[[1, 2]]), "models[0]"),
])
def test_a_damaged_document_names_the_file_and_field(damage, field):
    v = _view()
    doc = json.loads(json.dumps(objects_document(v)))
    damage(doc)
    with pytest.raises(ValueError) as e:
        _roundtrip(doc, objects_arrays(v))
    assert str(e.value).startswith("truth/v_objects.json") and field in str(e.value) and "\n" not in str(e.value)


def test_masks_that_do_not_match_the_document_are_refused():
    v = _view()
    arrays = objects_arrays(v)
    arrays["object_ids"] = np.array([7], np.uint32)
    with pytest.raises(ValueError, match="object_ids"):
        _roundtrip(objects_document(v), arrays)
