"""The COCO export (scenegen.export.coco) read back by pycocotools (COCO's own API): annotations,
masks (annToMask against our visible masks), boxes, keypoints and skeletons against the object
truth; COCOeval of the ground truth against itself gives AP 1 for masks and keypoints. The
articulated figure (one instance of eleven parts, 13 keypoints) and the table-top fixture."""
from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval

from scenegen.dataset import Dataset
from scenegen.export import export
from scenegen.export.coco import rle_counts

pytestmark = pytest.mark.render


def _coco(dataset, tmp_path_factory, name):
    dest = tmp_path_factory.mktemp(name) / "coco"
    export(dataset, "coco", dest)
    with contextlib.redirect_stdout(io.StringIO()):  # pycocotools prints its progress
        return Dataset(dataset), COCO(str(dest / "annotations.json"))


@pytest.fixture(scope="module")
def figure(figure_dataset, tmp_path_factory):
    return _coco(figure_dataset, tmp_path_factory, "coco_figure")


@pytest.fixture(scope="module")
def tabletop(objects_dataset, tmp_path_factory):
    return _coco(objects_dataset, tmp_path_factory, "coco_tabletop")


def test_rle_counts_decode_with_pycocotools():
    from pycocotools import mask as mask_utils
    rng = np.random.default_rng(0)
    for m in (rng.random((5, 7)) > 0.5, np.ones((3, 4), bool), np.zeros((2, 2), bool)):
        rle = mask_utils.frPyObjects({"size": list(m.shape), "counts": rle_counts(m)}, *m.shape)
        np.testing.assert_array_equal(mask_utils.decode(rle).astype(bool), m)


def test_instances_masks_and_boxes(tabletop):
    ds, coco = tabletop
    assert [c["name"] for c in coco.loadCats(coco.getCatIds())] == ["crate", "can", "stone"]
    n = 0
    for image_id, view in enumerate(ds.views, start=1):
        objs = ds.object_truth(view)
        ids = ds.truth(view)["object_id"]
        anns = coco.loadAnns(coco.getAnnIds(imgIds=[image_id]))
        seen = [o for o in objs.objects if o.px_count_visib > 0]
        assert [a["category_id"] for a in anns] == [o.model_id for o in seen]
        for a, o in zip(anns, seen):
            m = coco.annToMask(a).astype(bool)
            np.testing.assert_array_equal(m, ids == o.object_id)
            v, u = np.nonzero(m)
            assert a["bbox"] == [u.min(), v.min(), u.max() - u.min() + 1, v.max() - v.min() + 1]  # pixel edges
            assert a["area"] == m.sum() and a["iscrowd"] == 0
            n += 1
    assert n >= 6


def test_figure_is_one_instance_with_its_keypoints_and_skeleton(figure):
    ds, coco = figure
    cats = coco.loadCats(coco.getCatIds())
    assert [c["name"] for c in cats] == ["figure"]  # the parts are not categories of their own
    names = cats[0]["keypoints"]
    assert len(names) == 13 and len(cats[0]["skeleton"]) == 14
    assert ["nose", "left_shoulder"] in [[names[i - 1], names[j - 1]] for i, j in cats[0]["skeleton"]]
    flags = []
    for image_id, view in enumerate(ds.views, start=1):
        objs = ds.object_truth(view)
        (a,) = coco.loadAnns(coco.getAnnIds(imgIds=[image_id]))
        ids = ds.truth(view)["object_id"]
        np.testing.assert_array_equal(coco.annToMask(a).astype(bool), np.isin(ids, [o.object_id for o in objs.objects]))
        kp = np.reshape(a["keypoints"], (-1, 3))
        truth = {k.name: k for o in objs.objects for k in o.keypoints}
        for name, (x, y, v) in zip(names, kp):
            k = truth[name]
            expected = {"visible": 2, "self_occluded": 1, "occluded": 1, "out_of_image": 0}[k.state]
            assert v == expected
            if v:
                np.testing.assert_allclose([x, y], k.uv_px + 0.5, atol=1e-12)  # COCO = OpenCV + 0.5
            flags.append(k.state)
        assert a["num_keypoints"] == int((kp[:, 2] > 0).sum())
    assert {"visible", "self_occluded", "occluded"} <= set(flags)


def test_cocoeval_scores_the_ground_truth_against_itself_perfectly(figure, tabletop):
    for (ds, coco), iou_type in ((tabletop, "segm"), (figure, "keypoints")):
        results = [{**a, "score": 1.0} for a in coco.loadAnns(coco.getAnnIds())]
        with contextlib.redirect_stdout(io.StringIO()):
            dt = coco.loadRes(results)
            ev = COCOeval(coco, dt, iou_type)
            if iou_type == "keypoints":
                ev.params.kpt_oks_sigmas = np.full(13, 0.05)
            ev.evaluate()
            ev.accumulate()
            ev.summarize()
        assert ev.stats[0] == pytest.approx(1.0), iou_type
