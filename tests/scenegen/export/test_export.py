"""Exports read back by their own tools: pycolmap (COLMAP), cv2.FileStorage (OpenCV YAML), and
independent readers for KITTI, Middlebury, NeRF and TUM; the CLI's bad-input behaviour."""
import json

import cv2
import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset, codecs as sio
from scenegen.dataset.codecs import decode_pfm
from scenegen.geometry.conventions import cam_from_world_from_opengl
from scenegen.geometry.rotation import matrix_from_quat_wxyz

# pycolmap's projection of each exported 3D point vs ours: the bound (float64 both).
TOL_COLMAP_PX = 1e-6

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def ds(crossview_render):
    return Dataset(crossview_render[1])


def run_export(ds, fmt, tmp_path):
    dest = tmp_path / fmt
    assert main(["export", str(ds.root), "--format", fmt, "-o", str(dest)]) == 0
    return dest


def test_colmap_export_loads_in_pycolmap(ds, tmp_path):
    import pycolmap

    rec = pycolmap.Reconstruction(str(run_export(ds, "colmap", tmp_path)))
    assert rec.num_images() == len(ds.views) and rec.num_points3D() > 500
    worst, n = 0.0, 0
    cams = {v: ds.camera(v) for v in ds.views}  # Camera() measures its undistortion: build once
    for p in rec.points3D.values():
        assert p.track.length() >= 2
        for el in p.track.elements:
            im = rec.images[el.image_id]
            cam, pose = cams[im.name[: -len(".png")]]
            ours = cam.project(pose.apply(p.xyz[None]))[0] + 0.5  # COLMAP pixels
            worst = max(worst, float(np.abs(im.project_point(p.xyz) - ours).max()))
            # the stored 2D observation is that projection too
            worst = max(worst, float(np.abs(im.points2D[el.point2D_idx].xy - ours).max()))
            n += 1
    print(f"pycolmap vs ours over {n} observations: max {worst:.2e} px")
    assert worst < TOL_COLMAP_PX


def test_opencv_yaml_reads_in_filestorage(ds, tmp_path):
    dest = run_export(ds, "opencv", tmp_path)
    fs = cv2.FileStorage(str(dest / "cameras.yaml"), cv2.FILE_STORAGE_READ)
    views = fs.getNode("views")
    assert views.size() == len(ds.views)
    for k, v in enumerate(ds.views):
        node = views.at(k)
        cam, pose = ds.camera(v)
        assert node.getNode("name").string() == v
        assert np.array_equal(node.getNode("K").mat(), cam.K)
        assert np.array_equal(node.getNode("R").mat(), pose.R) and np.array_equal(node.getNode("T").mat().ravel(), pose.t)
    fs.release()
    fr = sio.read_json(ds.path("crossview/index.json"))["stereo"][0]
    fs = cv2.FileStorage(str(dest / f"stereo/{fr['left_view']}.yaml"), cv2.FILE_STORAGE_READ)
    K1, D1, K2, D2 = (fs.getNode(k).mat() for k in ("K1", "D1", "K2", "D2"))
    R, T, E, F = (fs.getNode(k).mat() for k in ("R", "T", "E", "F"))
    R1, R2, P1, P2 = (fs.getNode(k).mat() for k in ("R1", "R2", "P1", "P2"))
    size = tuple(int(x) for x in fs.getNode("image_size").mat().ravel())
    tx, ty, tz = T.ravel()
    assert np.allclose(E, np.array([[0, -tz, ty], [tz, 0, -tx], [-ty, tx, 0]]) @ R, atol=1e-15)  # [T]x R
    # what OpenCV itself derives from the written K, D, R, T
    cR1, cR2, cP1, cP2, *_ = cv2.stereoRectify(K1, D1, K2, D2, size, R, T, flags=cv2.CALIB_ZERO_DISPARITY,
                                               alpha=-1, newImageSize=size)
    assert np.allclose(cR1, R1, atol=1e-12) and np.allclose(cR2, R2, atol=1e-12)
    assert np.allclose(cP2[0, 3], P2[0, 3], rtol=1e-9)
    # F on undistorted pixels agrees with K, R, T
    Fk = np.linalg.inv(K2).T @ E @ np.linalg.inv(K1)
    assert np.allclose(Fk / Fk[2, 2], F, rtol=1e-9, atol=1e-12)
    fs.release()
    fs = cv2.FileStorage(str(dest / "pairs.yaml"), cv2.FILE_STORAGE_READ)
    assert fs.getNode("pairs").size() == 3
    fs.release()


def test_kitti_export_round_trips(ds, tmp_path):
    dest = run_export(ds, "kitti-stereo", tmp_path)
    frames = json.loads((dest / "frames.json").read_text())
    assert [f["index"] for f in frames] == ["000000", "000001"]
    for f in frames:
        png = cv2.imread(str(dest / f"training/disp_occ_0/{f['index']}_10.png"), cv2.IMREAD_UNCHANGED)
        assert png.dtype == np.uint16
        d = decode_pfm(ds.path(f"{f['stereo_dir']}/disp_left.pfm").read_bytes())
        ok = png > 0
        assert np.array_equal(ok, np.isfinite(d))
        assert np.abs(png[ok] / 256.0 - d[ok]).max() <= 0.5 / 256 + 1e-6
        img = cv2.imread(str(dest / f"training/image_2/{f['index']}_10.png"), cv2.IMREAD_UNCHANGED)
        assert img.dtype == np.uint8 and img.shape == (150, 200, 3)
        calib = dict(line.split(":", 1) for line in (dest / f"training/calib_cam_to_cam/{f['index']}.txt").read_text().splitlines())
        P2 = np.array(calib["P_rect_02"].split(), float).reshape(3, 4)
        P3 = np.array(calib["P_rect_03"].split(), float).reshape(3, 4)
        c = sio.read_json(ds.path(f"{f['stereo_dir']}/calib.json"))
        assert np.allclose(P2, c["P1"], rtol=1e-11) and np.allclose(P3, c["P2"], rtol=1e-11)
        assert -P3[0, 3] / P3[0, 0] == pytest.approx(0.12, rel=1e-11)


def test_middlebury_export_round_trips(ds, tmp_path):
    from scenegen.export.middlebury import read_calib

    dest = run_export(ds, "middlebury", tmp_path)
    fr = sio.read_json(ds.path("crossview/index.json"))["stereo"][0]
    folder = dest / "trainingF" / fr["left_view"]
    d0 = decode_pfm((folder / "disp0GT.pfm").read_bytes())
    assert np.array_equal(d0, decode_pfm(ds.path(f"{fr['dir']}/disp_left.pfm").read_bytes()), equal_nan=True)
    cal = read_calib((folder / "calib.txt").read_text())
    assert cal["baseline"] == pytest.approx(120.0, rel=1e-12)
    assert cal["width"] == 200 and cal["vmax"] >= np.max(d0[np.isfinite(d0)]) and cal["ndisp"] % 16 == 0
    # Middlebury's depth formula Z = baseline f / (d + doffs) gives back the rectified depth
    t = sio.read_exr(ds.path(f"{fr['dir']}/corr_left.exr"))
    mask = cv2.imread(str(folder / "mask0nocc.png"), cv2.IMREAD_UNCHANGED)
    assert set(np.unique(mask)) <= {0, 128, 255} and (mask == 255).sum() == (t["state"] == 1).sum()
    f = cal["cam0"][0, 0]
    Z = cal["baseline"] / 1000.0 * f / (d0 + cal["doffs"])
    c = sio.read_json(ds.path(f"{fr['dir']}/calib.json"))
    assert np.all(np.isfinite(Z[np.isfinite(d0)])) and f == pytest.approx(c["K"][0][0])


def test_nerf_and_tum_exports(ds, tmp_path):
    dest = run_export(ds, "nerf", tmp_path)
    doc = json.loads((dest / "transforms.json").read_text())
    assert len(doc["frames"]) == len(ds.views)
    for fr in doc["frames"]:
        v = fr["file_path"][len("images/"):-len(".png")]
        cam, pose = ds.camera(v)
        assert cam_from_world_from_opengl(fr["transform_matrix"]).allclose(pose, atol=1e-12)
        assert fr["cx"] == cam.cx + 0.5 and fr["fl_x"] == cam.fx and (dest / fr["file_path"]).is_file()
    dest = run_export(ds, "tum", tmp_path)
    lines = [l for l in (dest / "st_left.txt").read_text().splitlines() if not l.startswith("#")]
    assert len(lines) == 2
    for line, v in zip(lines, ("st_left_0000", "st_left_0001")):
        ts, tx, ty, tz, qx, qy, qz, qw = map(float, line.split())
        _, pose = ds.camera(v)
        wfc = pose.inverse()
        assert np.allclose([tx, ty, tz], wfc.t, atol=1e-12)
        assert np.allclose(matrix_from_quat_wxyz([qw, qx, qy, qz]), wfc.R, atol=1e-12)


def test_export_bad_input_exits_2(ds, tmp_path, capsys):
    assert main(["export", str(tmp_path / "missing"), "--format", "colmap"]) == 2
    assert "is not a directory" in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        main(["export", str(ds.root), "--format", "ply"])
    assert e.value.code == 2
    assert "invalid choice" in capsys.readouterr().err
    busy = tmp_path / "busy"
    busy.mkdir()
    (busy / "x").write_text("x")
    assert main(["export", str(ds.root), "--format", "tum", "-o", str(busy)]) == 2
    err = capsys.readouterr().err
    assert "not an empty folder" in err and "Traceback" not in err


def test_exports_do_not_import_mitsuba(ds, tmp_path):
    import subprocess
    import sys

    code = ("import sys; from scenegen.export import export; "
            f"[export({str(ds.root)!r}, f, {str(tmp_path)!r} + '/' + f) for f in ('colmap', 'opencv', 'tum', 'middlebury')]; "
            "assert 'mitsuba' not in sys.modules and 'drjit' not in sys.modules, 'imported a renderer'")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
