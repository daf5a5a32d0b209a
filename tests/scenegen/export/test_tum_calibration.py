"""The TUM export's calibration files (camera.txt, orbslam.yaml): read back with OpenCV's
FileStorage (what ORB-SLAM reads them with), they are each stream's camera, and cv2.projectPoints
with them images every truth point of the exported rgb/ at its pixel centre."""
import cv2
import numpy as np
import pytest

from scenegen.export import export
from scenegen.export.tum_calib import calibration_files, tum_parameters
from scenegen.geometry.camera import Camera
from scenegen.geometry.camera.interop import opencv_camera_args

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def tum(crossview_render, tmp_path_factory):
    from scenegen.dataset import Dataset

    ds = Dataset(crossview_render[1])
    dest = tmp_path_factory.mktemp("tum") / "tum"
    return ds, export(ds.root, "tum", dest), dest


def test_every_stream_has_its_cameras_calibration(tum):
    ds, summary, dest = tum
    assert set(summary["calibration"]) == set(summary["streams"]) and len(summary["streams"]) == 3
    for stream in summary["streams"]:
        assert summary["calibration"][stream] == "camera.txt, orbslam.yaml"
        view = sorted(v for v in ds.views if stream in (ds.view_info(v)["camera_name"],
                                                         f"{ds.view_info(v).get('rig')}_{ds.view_info(v).get('rig_member')}"))[0]
        cam = ds.camera(view)[0]
        (line,) = [ln for ln in (dest / stream / "camera.txt").read_text().splitlines() if not ln.startswith("#")]
        fx, fy, cx, cy, *d = map(float, line.split())
        K, dist = cam.to_opencv()
        assert [fx, fy, cx, cy] == [K[0, 0], K[1, 1], K[0, 2], K[1, 2]]
        assert d == list(dist) + [0.0] * (5 - len(dist))  # bit-exact (shortest round-trip text)
        fs = cv2.FileStorage(str(dest / stream / "orbslam.yaml"), cv2.FILE_STORAGE_READ)
        got = [fs.getNode(f"Camera.{k}").real() for k in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")]
        assert got == [fx, fy, cx, cy, *d]
        assert (fs.getNode("Camera.width").real(), fs.getNode("Camera.height").real()) == cam.size
        assert fs.getNode("DepthMapFactor").real() == 5000.0 and fs.getNode("Camera.RGB").real() == 1
        frames = len(list((dest / stream / "rgb").iterdir()))
        if frames > 1:
            assert fs.getNode("Camera.fps").real() == 1.0  # a static scene: timestamps are frame indices
        else:
            assert fs.getNode("Camera.fps").empty()  # one frame: ORB-SLAM's default
        assert fs.getNode("ORBextractor.nFeatures").real() == 1000
        fs.release()
        # the file describes the exported images: truth points project to their pixel centres
        truth = ds.truth(view)
        P = truth["points_cam"][truth["valid"]]
        uv, _ = cv2.projectPoints(P, np.zeros(3), np.zeros(3), np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1.0]]),
                                  np.array(d))
        vv, uu = np.nonzero(truth["valid"])
        err = np.abs(uv.reshape(-1, 2) - np.stack([uu, vv], 1)).max()
        print(f"{stream}: truth points through the exported calibration: max {err:.2e} px from their pixel centres")
        assert err < 1e-3, err  # float32 truth points


def test_cameras_the_format_cannot_hold_get_a_reason_not_a_file():
    fish = Camera.from_opencv_fisheye(np.array([[200, 0, 99.5], [0, 200, 74.5], [0, 0, 1.0]]), (0.1, 0, 0, 0), (200, 150))
    skewed = Camera(*opencv_camera_args(np.array([[200, 0.5, 99.5], [0, 200, 74.5], [0, 0, 1.0]]), None, (200, 150)))
    rational = Camera.from_opencv(np.array([[200, 0, 99.5], [0, 200, 74.5], [0, 0, 1.0]]),
                                  (0.1, 0, 0, 0, 0, 0.01, 0, 0), (200, 150))
    for cam, why in ((fish, "fisheye"), (skewed, "skew"), (rational, "rational")):
        params, reason = tum_parameters(cam)
        assert params is None and why in reason
        assert isinstance(calibration_files("s", "c", cam, [0.0, 0.1]), str)
    pin = Camera.from_fov(60, (64, 48))
    files = calibration_files("s", "c", pin, [0.0, 0.1, 0.2])
    assert b"Camera.fps: 10.0" in files["orbslam.yaml"] and b"Camera.k3: 0.0" in files["orbslam.yaml"]
