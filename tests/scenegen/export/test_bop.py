"""The BOP export (scenegen.export.bop) read back by bop_toolkit's own loaders (a verbatim copy,
tests/scenegen/export/bop_toolkit_copy.py: bop_toolkit is not on PyPI) and checked against the
dataset's truth and bop_toolkit's own box and diameter functions; the session fixture
``objects_dataset`` (64x48, two views); and the refusals."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

from scenegen.dataset import Dataset
from scenegen.export import export
from scenegen.export.errors import ExportError

sys.path.insert(0, str(Path(__file__).parent))
import bop_toolkit_copy as bop  # noqa: E402

pytestmark = pytest.mark.render
SCENE = "test/000000"


@pytest.fixture(scope="module")
def exported(objects_dataset, tmp_path_factory):
    dest = tmp_path_factory.mktemp("bop") / "bop"
    summary = export(objects_dataset, "bop", dest)
    return Dataset(objects_dataset), dest, summary


def test_bop_toolkit_reads_the_poses_cameras_and_depth(exported):
    ds, dest, summary = exported
    gt = bop.load_scene_gt(dest / SCENE / "scene_gt.json")
    cams = bop.load_scene_camera(dest / SCENE / "scene_camera.json")
    assert sorted(gt) == sorted(cams) == list(range(len(ds.views))) and summary["images"] == len(ds.views)
    for im_id, view in enumerate(ds.views):
        objs = ds.object_truth(view)
        camera, cam_from_world = ds.camera(view)
        np.testing.assert_array_equal(cams[im_id]["cam_K"], camera.K)
        np.testing.assert_allclose(cams[im_id]["cam_R_w2c"], cam_from_world.R, atol=0)
        np.testing.assert_allclose(cams[im_id]["cam_t_w2c"].ravel(), cam_from_world.t * 1000, rtol=1e-15)
        assert [g["obj_id"] for g in gt[im_id]] == [o.model_id for o in objs.objects]
        for g, o in zip(gt[im_id], objs.objects):
            np.testing.assert_allclose(g["cam_R_m2c"], o.cam_from_object.R, atol=0)
            np.testing.assert_allclose(g["cam_t_m2c"].ravel(), o.cam_from_object.t * 1000, rtol=1e-15)
        depth_mm = bop.load_depth(dest / SCENE / "depth" / f"{im_id:06d}.png") * cams[im_id]["depth_scale"]
        truth = ds.truth(view)
        valid = truth["valid"]
        assert (depth_mm[~valid] == 0).all()
        np.testing.assert_allclose(depth_mm[valid], truth["depth_z"][valid] * 1000, atol=cams[im_id]["depth_scale"] / 2 + 1e-6)
        rgb = bop.load_im(dest / SCENE / "rgb" / f"{im_id:06d}.png")
        np.testing.assert_array_equal(rgb, ds.image(view))


def test_masks_and_gt_info_as_calc_gt_info_writes_them(exported):
    ds, dest, _ = exported
    infos = bop.load_json(dest / SCENE / "scene_gt_info.json", keys_to_int=True)
    for im_id, view in enumerate(ds.views):
        objs = ds.object_truth(view)
        ids = ds.truth(view)["object_id"]
        depth = bop.load_depth(dest / SCENE / "depth" / f"{im_id:06d}.png")
        for gt_id, o in enumerate(objs.objects):
            info = infos[im_id][gt_id]
            mask = bop.load_im(dest / SCENE / "mask" / f"{im_id:06d}_{gt_id:06d}.png") > 0
            visib = bop.load_im(dest / SCENE / "mask_visib" / f"{im_id:06d}_{gt_id:06d}.png") > 0
            np.testing.assert_array_equal(visib, ids == o.object_id)
            np.testing.assert_array_equal(mask, objs.mask_full[gt_id])
            assert info["px_count_visib"] == visib.sum() == o.px_count_visib
            assert info["px_count_valid"] == np.sum(depth[mask] > 0)  # calc_gt_info.py's count
            assert info["px_count_all"] == o.px_count_all >= mask.sum()
            assert info["visib_fract"] == pytest.approx(info["px_count_visib"] / info["px_count_all"], rel=1e-15)
            if info["px_count_visib"] > 0:
                ys, xs = visib.nonzero()
                assert info["bbox_visib"] == [int(e) for e in bop.calc_2d_bbox(xs, ys)]
                if not _touches_border(mask):  # the silhouette lies within the image: its box is the mask's
                    ys, xs = mask.nonzero()
                    assert info["bbox_obj"] == [int(e) for e in bop.calc_2d_bbox(xs, ys)]
            else:
                assert info["bbox_obj"] == info["bbox_visib"] == [-1, -1, -1, -1]


def _touches_border(mask) -> bool:
    return bool(mask[0].any() or mask[-1].any() or mask[:, 0].any() or mask[:, -1].any())


def test_models_and_models_info(exported):
    ds, dest, summary = exported
    info = bop.load_json(dest / "models" / "models_info.json", keys_to_int=True)
    objs = ds.object_truth(ds.views[0])
    assert sorted(info) == [m.model_id for m in objs.models] == [1, 2, 3] and summary["models"] == 3
    for m in objs.models:
        model = bop.load_ply(dest / "models" / f"obj_{m.model_id:06d}.ply")
        pts = model["pts"]
        assert "normals" in model and len(model["faces"]) > 0
        first = [o for o in objs.objects if o.model_id == m.model_id][0]
        ours = ds.mesh(first.name).copy()
        ours.apply_transform(first.world_from_mesh_object.inverse().matrix)
        np.testing.assert_allclose(pts, ours.vertices * 1000, atol=1e-5)  # 8 decimals of mm in the ASCII PLY
        e = info[m.model_id]
        assert e["diameter"] == pytest.approx(bop.calc_pts_diameter2(pts), abs=1e-4)
        for k, axis in enumerate("xyz"):
            assert e[f"min_{axis}"] == pytest.approx(pts[:, k].min(), abs=1e-5)
            assert e[f"size_{axis}"] == pytest.approx(np.ptp(pts[:, k]), abs=1e-5)
    crate, can = info[1], info[2]
    S = np.reshape(crate["symmetries_discrete"][0], (4, 4))  # as misc.get_symmetry_transformations reads it
    np.testing.assert_allclose(S[:3, :3], np.diag([-1.0, -1.0, 1.0]), atol=1e-15)
    pts = bop.load_ply(dest / "models" / "obj_000001.ply")["pts"]
    moved = pts @ S[:3, :3].T + S[:3, 3]
    assert cKDTree(pts).query(moved)[0].max() < 1e-4  # the declared symmetry maps the model onto itself (mm)
    assert can["symmetries_continuous"] == [{"axis": [0.0, 0.0, 1.0], "offset": [0.0, 0.0, 10.0]}]
    assert "symmetries_discrete" not in can and "symmetries_continuous" not in info[3]


def test_test_targets_as_enumerate_test_targets_lists_them(exported):
    ds, dest, _ = exported
    targets = bop.load_json(dest / "test_targets_bop19.json")
    gt = bop.load_scene_gt(dest / SCENE / "scene_gt.json")
    infos = bop.load_json(dest / SCENE / "scene_gt_info.json", keys_to_int=True)
    expected = []
    for im_id in sorted(gt):
        counts: dict[int, int] = {}
        for g, i in zip(gt[im_id], infos[im_id]):
            if i["visib_fract"] >= 0.1:
                counts[g["obj_id"]] = counts.get(g["obj_id"], 0) + 1
        expected += [{"scene_id": 0, "im_id": im_id, "obj_id": k, "inst_count": c} for k, c in counts.items()]
    assert targets == expected


def test_a_dataset_without_object_truth_is_refused(crossview_render, tmp_path):
    with pytest.raises(ExportError, match="truth: {objects: true}"):
        export(crossview_render[1], "bop", tmp_path / "bop")
    assert not (tmp_path / "bop").exists()


FIXTURE = Path(__file__).parents[2] / "data" / "bop_objects_tabletop"


def test_the_committed_export_of_objects_tabletop_holds_together():
    """tests/data/bop_objects_tabletop (the readers' fixture, scenes/objects_tabletop.yaml
    exported) read by bop_toolkit's loaders: masks, counts, boxes, depth and models agree."""
    gt = bop.load_scene_gt(FIXTURE / SCENE / "scene_gt.json")
    cams = bop.load_scene_camera(FIXTURE / SCENE / "scene_camera.json")
    infos = bop.load_json(FIXTURE / SCENE / "scene_gt_info.json", keys_to_int=True)
    models = bop.load_json(FIXTURE / "models" / "models_info.json", keys_to_int=True)
    assert sorted(gt) == sorted(cams) == sorted(infos) == [0, 1, 2] and sorted(models) == [1, 2, 3]
    assert sum(len(g) for g in gt.values()) == 18
    for im_id in gt:
        depth = bop.load_depth(FIXTURE / SCENE / "depth" / f"{im_id:06d}.png") * cams[im_id]["depth_scale"]
        K = cams[im_id]["cam_K"]
        for gt_id, (g, info) in enumerate(zip(gt[im_id], infos[im_id])):
            visib = bop.load_im(FIXTURE / SCENE / "mask_visib" / f"{im_id:06d}_{gt_id:06d}.png") > 0
            mask = bop.load_im(FIXTURE / SCENE / "mask" / f"{im_id:06d}_{gt_id:06d}.png") > 0
            assert info["px_count_visib"] == visib.sum() and not (visib & ~mask).any()
            assert info["px_count_all"] >= mask.sum() and info["px_count_valid"] == np.sum(depth[mask] > 0)
            if visib.any():
                ys, xs = visib.nonzero()
                assert info["bbox_visib"] == [int(e) for e in bop.calc_2d_bbox(xs, ys)]
            model = bop.load_ply(FIXTURE / "models" / f"obj_{g['obj_id']:06d}.ply")
            mesh = trimesh.Trimesh(model["pts"], model["faces"].astype(int), process=False)
            v, u = np.nonzero(visib)
            X = depth[v, u][:, None] * (np.linalg.inv(K) @ np.stack([u, v, np.ones_like(u)]).astype(float)).T
            X_model = (X - g["cam_t_m2c"].T) @ g["cam_R_m2c"]  # R^T (X - t), mm
            dist = trimesh.proximity.closest_point(mesh, X_model)[1]
            # the visible pixels' depth lands on the model at the stored pose, within the depth's
            # rounding: z to depth_scale / 2 (0.05 mm), along a ray at most 1.1x longer (measured
            # max 0.0496 mm)
            assert dist.max() < cams[im_id]["depth_scale"], (im_id, gt_id, dist.max())
