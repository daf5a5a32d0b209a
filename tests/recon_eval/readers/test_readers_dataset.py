"""The evaluator's view of a scenegen dataset (recon_eval.readers.scenegen_dataset) on the analytic
plane dataset of conftest.py: poses, cameras, depth, disparity, held-out points, meshes, errors."""
import shutil
import subprocess
import sys

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from scenegen.dataset import Dataset, TruthKind


class TestScenegenDataset:
    def test_poses_cameras_depth(self, plane_dataset, plane_scene):
        root, cams = plane_dataset
        assert is_dataset(root) and not is_dataset(root / "cameras.json")
        d = read_dataset(root)
        assert d.views == ("left_000", "right_000", "free_000")
        P = d.poses
        for k, v in enumerate(d.views):
            np.testing.assert_array_equal(P.R_cam_from_world[k], cams[v][1].R)  # JSON float64 is exact
            np.testing.assert_array_equal(P.t_cam_from_world[k], cams[v][1].t)
        assert d.camera("free_000")[0] == plane_scene.DISTORTED
        depth = d.depth("left_000")  # looking straight down from 3 m: depth_z = 3 everywhere seen
        assert depth.dtype == np.float64 and np.allclose(depth[np.isfinite(depth)], plane_scene.HEIGHT_M, rtol=1e-7)

    def test_disparity_of_the_rectified_pair(self, plane_dataset, plane_scene):
        d = read_dataset(plane_dataset[0])
        disp = d.disparity("left_000")
        assert np.allclose(disp, plane_scene.PINHOLE.fx * plane_scene.BASELINE_M / plane_scene.HEIGHT_M, rtol=1e-7)
        with pytest.raises(InputError, match="rig is null"):
            d.disparity("free_000")
        with pytest.raises(InputError, match="identical pinhole"):
            d.disparity("left_000", "free_000")

    def test_correspondences_are_exact_and_visible(self, plane_dataset, plane_scene):
        d = read_dataset(plane_dataset[0])
        x1, x2 = d.correspondences("left_000", "right_000")
        assert len(x1) > 500
        # rectified: same row, shifted by the disparity (float32 truth storage: ~1e-6 px)
        np.testing.assert_allclose(x2[:, 1], x1[:, 1], atol=1e-4)
        np.testing.assert_allclose(x1[:, 0] - x2[:, 0], plane_scene.PINHOLE.fx * plane_scene.BASELINE_M / plane_scene.HEIGHT_M, atol=1e-4)

    def test_held_out_points_reproject(self, plane_dataset):
        d = read_dataset(plane_dataset[0])
        uv, X = d.points_at_pixels("free_000", max_points=200)
        cam, pose = d.camera("free_000")
        assert len(uv) == 200
        np.testing.assert_allclose(cam.project(pose.apply(X)), uv, atol=1e-3)  # float32 storage

    def test_mesh_and_errors(self, plane_dataset, tmp_path):
        d = read_dataset(plane_dataset[0])
        V, F = d.mesh()
        assert V.shape == (4, 3) and F.shape == (2, 3)
        with pytest.raises(InputError, match="'nope' is not a complete view"):
            d.depth("nope")
        with pytest.raises(InputError, match="not a scenegen dataset"):
            read_dataset(tmp_path)

    def test_dataset_accessors_with_the_evaluators_errors(self, plane_dataset, tmp_path):
        """Every Dataset accessor is reached through DatasetTruth, with its errors as InputError."""
        d, ds = read_dataset(plane_dataset[0]), Dataset(plane_dataset[0])
        v = d.views[0]
        assert d.dataset.root == ds.root and d.scene_name == ds.scene_name and d.objects == ds.objects
        assert np.array_equal(d.image(v), ds.image(v)) and d.image_path(v) == ds.image_path(v)
        assert np.array_equal(d.object_ids(v), ds.truth(v)[TruthKind.OBJECT_ID])
        assert d.views_of_camera(d.view_info(v)["camera_name"]) == ds.views_of_camera(ds.view_info(v)["camera_name"])
        with pytest.raises(InputError, match="'nope' is not a complete view"):
            d.image("nope")
        with pytest.raises(AttributeError):
            d.no_such_accessor
        damaged = tmp_path / "damaged"
        shutil.copytree(plane_dataset[0], damaged)
        (damaged / "truth" / f"{v}_ids.exr").write_bytes(b"not an EXR")
        with pytest.raises(InputError, match=rf"truth/{v}_ids\.exr: unreadable object ids"):
            read_dataset(damaged).object_ids(v)


def test_readers_import_no_mitsuba(plane_dataset):
    code = ("import sys\n"
            "from recon_eval.readers import scenegen_dataset, nerf, kitti_odometry, exr, opencv_calib, pose_file\n"
            f"d = scenegen_dataset.read_dataset({str(plane_dataset[0])!r}); d.depth('left_000'); d.camera('free_000')\n"
            "import recon_eval.report.plots, recon_eval.report.html\n"
            "assert not any(m.split('.')[0] in ('mitsuba', 'drjit') for m in sys.modules), 'mitsuba imported'\n")
    subprocess.run([sys.executable, "-c", code], check=True)
