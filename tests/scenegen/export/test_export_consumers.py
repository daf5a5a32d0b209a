"""Exports loaded the way their consumers load them: pycolmap for the COLMAP and 3D Gaussian
Splatting models (with 3DGS's own camera rules), nerfstudio's / instant-ngp's transforms.json
rules written out here, pykitti's calib parser, the MiddEval3 SDK's names, TUM RGB-D's layout,
OpenCV's EXR reader for the rectification maps, the KITTI odometry devkit's files and evo's KITTI
reader; a refused export leaves no folder behind."""
import json
import math
import os
import subprocess
import sys

import cv2
import numpy as np
import pytest
from evo.tools import file_interface

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.dataset.codecs import decode_pfm
from scenegen.dataset.layout import stereo_path
from scenegen.geometry.rotation import matrix_from_quat_wxyz

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def ds(crossview_render):
    return Dataset(crossview_render[1])


NO_CROSSVIEW = """
name: orbit
render: {spp: 4}
objects:
  - {name: floor, shape: {type: plane, size: [4, 4]}}
  - {name: ball, shape: {type: sphere, radius: 0.3}, transform: {translation: [0, 0, 0.3]}}
lights: [{type: constant, radiance: 0.5}]
cameras: {cam: {model: opencv, size: [64, 48], fx: 50, dist: [-0.05, 0.01, 0, 0]}}
views: [{camera: cam, orbit: {radius_m: 2, count: 3}}]
"""


@pytest.fixture(scope="module")
def orbit(tmp_path_factory):
    """A dataset rendered without a crossview: section (no tracks between views)."""
    from scenegen.pipeline.run import render_spec

    root = tmp_path_factory.mktemp("orbit")
    (root / "orbit.yaml").write_text(NO_CROSSVIEW)
    render_spec(root / "orbit.yaml", root / "out", progress=False)
    return Dataset(root / "out")


def run_export(ds, fmt, tmp_path, capsys=None):
    dest = tmp_path / fmt
    assert main(["export", str(ds.root), "--format", fmt, "-o", str(dest)]) == 0
    if capsys is not None:  # progress on stderr, counted
        err = capsys.readouterr().err
        assert f"scenegen: export {fmt}: " in err and "/" in err and " views (" in err
    return dest


def test_colmap_cameras_are_shared_per_physical_camera(ds, tmp_path):
    import pycolmap

    rec = pycolmap.Reconstruction(str(run_export(ds, "colmap", tmp_path)))
    names = {ds.view_info(v)["camera_name"] for v in ds.views}
    assert rec.num_cameras() == len(names) == 3 and rec.num_images() == len(ds.views) == 5
    by_name = {}
    for im in rec.images.values():
        by_name.setdefault(ds.view_info(im.name[:-4])["camera_name"], set()).add(im.camera_id)
    assert all(len(ids) == 1 for ids in by_name.values()) and len(set().union(*by_name.values())) == 3


def test_gaussian_splatting_layout_loads_in_pycolmap_with_3dgs_rules(ds, tmp_path):
    import pycolmap

    dest = run_export(ds, "gaussian-splatting", tmp_path)
    rec = pycolmap.Reconstruction(str(dest / "sparse" / "0"))
    assert rec.num_images() == 5 and rec.num_cameras() == 3 and rec.num_points3D() > 500
    # 3DGS's readColmapCameras: only PINHOLE / SIMPLE_PINHOLE; FovX = 2 atan(w / (2 fx)), images/<name>
    for im in rec.images.values():
        c = rec.cameras[im.camera_id]
        assert c.model.name in ("PINHOLE", "SIMPLE_PINHOLE")
        cam, pose = ds.camera(im.name[:-4])
        assert list(c.params) == [cam.fx, cam.fy, cam.cx + 0.5, cam.cy + 0.5]
        assert 2 * math.atan(c.width / (2 * c.params[0])) == pytest.approx(2 * math.atan(cam.width / (2 * cam.fx)))
        img = cv2.imread(str(dest / "images" / im.name), cv2.IMREAD_UNCHANGED)
        assert img.shape[:2] == (c.height, c.width)
        # the image is the real one resampled onto the pinhole: what OpenCV's own undistortion gives
        K, D = cam.to_opencv()
        m1, m2 = cv2.initUndistortRectifyMap(K, D, None, K, (cam.width, cam.height), cv2.CV_32FC1)
        ref = cv2.remap(cv2.imread(str(ds.path(f"images/{im.name}")), cv2.IMREAD_UNCHANGED), m1, m2, cv2.INTER_LINEAR)
        inner = (slice(4, -4), slice(4, -4))
        diff = np.abs(img[inner].astype(int) - ref[inner].astype(int))
        assert diff.max() <= 1 and diff.mean() < 0.01  # measured: identical (max 0)
    worst = 0.0
    for p in rec.points3D.values():
        assert p.track.length() >= 2
        for el in p.track.elements:
            im = rec.images[el.image_id]
            cam, pose = ds.camera(im.name[:-4])
            Xc = pose.apply(p.xyz[None])[0]  # the ideal pinhole, from scratch (COLMAP pixels)
            ours = np.array([cam.fx * Xc[0] / Xc[2] + cam.cx + 0.5, cam.fy * Xc[1] / Xc[2] + cam.cy + 0.5])
            worst = max(worst, float(np.abs(im.points2D[el.point2D_idx].xy - ours).max()),
                        float(np.abs(im.project_point(p.xyz) - ours).max()))
    assert worst < 1e-9


@pytest.mark.parametrize("fmt, folder", [("colmap", ""), ("gaussian-splatting", "sparse/0")])
def test_models_without_crossview_truth_have_single_view_points(orbit, tmp_path, fmt, folder):
    import pycolmap

    rec = pycolmap.Reconstruction(str(run_export(orbit, fmt, tmp_path) / folder))
    assert rec.num_images() == 3 and rec.num_cameras() == 1 and rec.num_points3D() > 50
    for p in rec.points3D.values():
        (el,) = p.track.elements  # observed in its own view only
        im = rec.images[el.image_id]
        xy = im.points2D[el.point2D_idx].xy
        assert np.abs(im.project_point(p.xyz) - xy).max() < 1e-9
        if fmt == "colmap":  # the real camera: the point is the truth of a grid pixel centre
            assert np.abs(xy - 0.5 - np.round((xy - 0.5) / 8) * 8).max() < 1e-3


def _distort_opencv(x, y, k1, k2, k3, k4, p1, p2):
    """nerfstudio's OPENCV model: radial 1 + k1 r^2 + k2 r^4 + k3 r^6 + k4 r^8, tangential p1 p2."""
    r2 = x * x + y * y
    radial = 1 + r2 * (k1 + r2 * (k2 + r2 * (k3 + r2 * k4)))
    return (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y)


def _nerf_frame_intrinsics(doc, fr):
    """instant-ngp / nerfstudio: a frame's value, else the top level; fl_x from camera_angle_x."""
    get = lambda k: fr.get(k, doc.get(k))  # noqa: E731
    fl_x = get("fl_x")
    if fl_x is None:
        fl_x = 0.5 * get("w") / math.tan(0.5 * doc["camera_angle_x"])
    return fl_x, get("fl_y") or fl_x, get("cx"), get("cy"), [get(k) or 0.0 for k in ("k1", "k2", "k3", "k4", "p1", "p2")]


def test_nerf_transforms_by_the_consumer_rules(ds, tmp_path, capsys):
    dest = run_export(ds, "nerf", tmp_path, capsys)
    doc = json.loads((dest / "transforms.json").read_text())
    files = [f["file_path"] for f in doc["frames"]]
    train, test = doc["train_filenames"], doc["test_filenames"]
    assert sorted(train + test) == sorted(files) and not set(train) & set(test) and test == [files[0]]
    assert doc["val_filenames"] == test
    for split, names in (("train", train), ("test", test), ("val", test)):
        sub = json.loads((dest / f"transforms_{split}.json").read_text())
        assert [f["file_path"] for f in sub["frames"]] == names
    worst_px, worst_mm = 0.0, 0.0
    for fr in doc["frames"]:
        v = os.path.basename(fr["file_path"])[:-4]
        truth = ds.truth(v)
        # paths are relative to the json's folder
        img = cv2.imread(str(dest / fr["file_path"]), cv2.IMREAD_UNCHANGED)
        depth = cv2.imread(str(dest / fr["depth_file_path"]), cv2.IMREAD_UNCHANGED)
        mask = cv2.imread(str(dest / fr["mask_path"]), cv2.IMREAD_UNCHANGED)
        assert img.shape[:2] == depth.shape == mask.shape == (fr["h"], fr["w"])
        assert depth.dtype == np.uint16 and mask.dtype == np.uint8 and mask.ndim == 2
        assert np.array_equal(mask > 0, truth["valid"])  # nerfstudio: nonzero = used
        z = depth * 1e-3  # nerfstudio's default depth_unit_scale_factor
        assert fr["depth_path"] == fr["depth_file_path"] and doc["integer_depth_scale"] == 1e-3  # instant-ngp
        ok = truth["valid"]
        assert np.array_equal(depth > 0, ok)
        worst_mm = max(worst_mm, float(np.abs(z[ok] - truth["depth_z"][ok]).max()) * 1e3)
        # c2w with OpenGL axes: a truth point lands on its pixel centre (nerfstudio: centre = i + 0.5)
        fl_x, fl_y, cx, cy, dist = _nerf_frame_intrinsics(doc, fr)
        c2w = np.array(fr["transform_matrix"])
        jj, ii = np.nonzero(ok)
        sel = slice(None, None, 37)
        X = truth["points_world"][jj[sel], ii[sel]].astype(np.float64)
        Xgl = (np.linalg.inv(c2w) @ np.c_[X, np.ones(len(X))].T)[:3].T
        x, y = Xgl[:, 0] / -Xgl[:, 2], -Xgl[:, 1] / -Xgl[:, 2]  # OpenGL looks down -z, y up
        xd, yd = _distort_opencv(x, y, *dist)
        u, vv = fl_x * xd + cx, fl_y * yd + cy
        worst_px = max(worst_px, float(np.abs(u - (ii[sel] + 0.5)).max()), float(np.abs(vv - (jj[sel] + 0.5)).max()))
    print(f"transforms.json: reprojection {worst_px:.2e} px, depth {worst_mm:.3f} mm")
    assert worst_px < 1e-4 and worst_mm <= 0.5 + 1e-3  # measured 5.4e-6 px (float32 truth points), 0.500 mm


def _pykitti_calib(path):
    """pykitti.utils.read_calib_file: 'key: floats', lines that are not numbers skipped."""
    data = {}
    for line in path.read_text().splitlines():
        key, value = line.split(":", 1)
        try:
            data[key] = np.array([float(x) for x in value.split()])
        except ValueError:
            pass
    return data


def test_kitti_calib_cam_to_cam_and_obj_map(ds, tmp_path):
    dest = run_export(ds, "kitti-stereo", tmp_path)
    frames = json.loads((dest / "frames.json").read_text())
    for f in frames:
        fr = ds.crossview.stereo(f["left_view"])
        cal = _pykitti_calib(dest / f"training/calib_cam_to_cam/{f['index']}.txt")
        P = {k: cal[f"P_rect_{k}"].reshape(3, 4) for k in ("00", "01", "02", "03")}  # pykitti's raw loader
        R_rect_00 = cal["R_rect_00"].reshape(3, 3)
        assert -P["03"][0, 3] / P["03"][0, 0] == pytest.approx(fr.baseline_m, rel=1e-11)
        (cl, pl), (_, pr) = ds.camera(f["left_view"]), ds.camera(f["right_view"])
        assert np.allclose(cal["K_02"].reshape(3, 3), cl.K) and np.allclose(cal["D_02"], cl.to_opencv()[1].ravel())
        # a raw left point through KITTI's chain P_rect_02 R_rect_00 lands where the rectified truth says
        t = ds.truth(f["left_view"])
        X = t["points_world"][t["valid"]][::41].astype(np.float64)
        x = P["02"] @ np.c_[(R_rect_00 @ pl.apply(X).T).T, np.ones(len(X))].T
        uv = (x[:2] / x[2]).T
        ref = fr.camera.project(fr.cam_from_world("left").apply(X))
        assert np.abs(uv - ref).max() < 1e-9  # measured 5.8e-12
        # T_03: the right camera in the frame of camera 00
        R03, T03 = cal["R_03"].reshape(3, 3), cal["T_03"]
        assert np.allclose(R03 @ pl.apply(X).T + T03[:, None], pr.apply(X).T, atol=1e-9)
        # obj_map: 0 exactly where there is no surface; elsewhere the instance the raw view sees there
        om = cv2.imread(str(dest / f"training/obj_map/{f['index']}_10.png"), cv2.IMREAD_UNCHANGED)
        assert om.dtype == np.uint8
        assert np.array_equal(om > 0, np.isfinite(fr.disparity("left")))
        raw_ids = ds.truth(f["left_view"])["instance_id"]
        m = fr.rectification_map("left")
        ui, vi = np.rint(m[..., 0]).astype(int), np.rint(m[..., 1]).astype(int)
        inside = (ui >= 1) & (vi >= 1) & (ui < cl.width - 1) & (vi < cl.height - 1)
        uniform = np.zeros_like(inside)
        pad = np.pad(raw_ids.astype(np.int64), 1, mode="edge")
        same = np.ones(raw_ids.shape, bool)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                same &= pad[1 + dy:1 + dy + raw_ids.shape[0], 1 + dx:1 + dx + raw_ids.shape[1]] == raw_ids
        uniform[inside] = same[vi[inside], ui[inside]]
        assert uniform.sum() > 0.8 * uniform.size
        assert np.array_equal(om[uniform], raw_ids[vi[uniform], ui[uniform]])


def test_middlebury_middeval3_names(ds, tmp_path):
    dest = run_export(ds, "middlebury", tmp_path)
    for fr in ds.crossview.stereo_frames():
        folder = dest / "trainingF" / fr.left_view
        assert sorted(p.name for p in folder.iterdir()) == ["calib.txt", "disp0GT.pfm", "disp1GT.pfm", "im0.png",
                                                            "im1.png", "mask0nocc.png", "mask1nocc.png"]
        keys = [line.split("=")[0] for line in (folder / "calib.txt").read_text().splitlines()]
        assert keys == ["cam0", "cam1", "doffs", "baseline", "width", "height", "ndisp", "isint", "vmin", "vmax",
                        "dyavg", "dymax"]
        for k, side in enumerate(("left", "right")):
            d = decode_pfm((folder / f"disp{k}GT.pfm").read_bytes())
            assert np.array_equal(d, fr.disparity(side))
            mask = cv2.imread(str(folder / f"mask{k}nocc.png"), cv2.IMREAD_UNCHANGED)
            assert np.array_equal(mask == 255, fr.correspondence(side).state == 1)


def test_tum_rgbd_layout(ds, tmp_path):
    dest = run_export(ds, "tum", tmp_path)
    root = dest / "st_left"
    rows = lambda p: [ln.split() for ln in p.read_text().splitlines() if ln and not ln.startswith("#")]  # noqa: E731
    rgb, depth, assoc = rows(root / "rgb.txt"), rows(root / "depth.txt"), rows(root / "associations.txt")
    gt = rows(root / "groundtruth.txt")
    assert [r[0] for r in rgb] == [r[0] for r in depth] == [r[0] for r in gt] == ["0.000000", "1.000000"]
    assert assoc == [[a[0], a[1], b[0], b[1]] for a, b in zip(rgb, depth)]
    assert (root / "groundtruth.txt").read_text() == (dest / "st_left.txt").read_text()
    for (ts, f_rgb), (_, f_d), v in zip(rgb, depth, ("st_left_0000", "st_left_0001")):
        assert f_rgb == f"rgb/{ts}.png" and f_d == f"depth/{ts}.png"
        d = cv2.imread(str(root / f_d), cv2.IMREAD_UNCHANGED)
        t = ds.truth(v)
        assert d.dtype == np.uint16 and np.array_equal(d > 0, t["valid"])
        assert np.abs(d[t["valid"]] / 5000.0 - t["depth_z"][t["valid"]]).max() <= 0.5 / 5000 + 1e-6
        assert cv2.imread(str(root / f_rgb)).shape == (150, 200, 3)
    for (ts, tx, ty, tz, qx, qy, qz, qw), v in zip(gt, ("st_left_0000", "st_left_0001")):
        wfc = ds.camera(v)[1].inverse()
        assert np.allclose([float(tx), float(ty), float(tz)], wfc.t, atol=1e-12)
        assert np.allclose(matrix_from_quat_wxyz([float(qw), float(qx), float(qy), float(qz)]), wfc.R, atol=1e-12)


def test_rectification_maps_read_in_opencv(ds, tmp_path):
    fr = ds.crossview.stereo_frames()[0]
    path = ds.path(stereo_path(fr.left_view, "map", "left"))
    code = ("import cv2, numpy as np, sys; m = cv2.imread(sys.argv[1], cv2.IMREAD_UNCHANGED); "
            "np.save(sys.argv[2], m)")
    out = tmp_path / "m.npy"
    env = dict(os.environ, OPENCV_IO_ENABLE_OPENEXR="1")
    r = subprocess.run([sys.executable, "-c", code, str(path), str(out)], env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    m = np.load(out)
    ours = fr.rectification_map("left")
    assert m.dtype == np.float32 and m.shape == ours.shape[:2] + (3,)
    assert np.array_equal(m[..., 2], ours[..., 0]) and np.array_equal(m[..., 1], ours[..., 1])
    # the docs' recipe: cv2.remap of the raw image with map (x, y) = BGR channels 2, 1
    raw = cv2.imread(str(ds.path(f"images/{fr.left_view}.png")), cv2.IMREAD_UNCHANGED)
    a = cv2.remap(raw, np.ascontiguousarray(m[..., 2:0:-1]), None, cv2.INTER_LINEAR)
    b = cv2.remap(raw, ours[..., 0], ours[..., 1], cv2.INTER_LINEAR)
    assert np.array_equal(a, b)


def test_refused_export_leaves_no_folder(ds, tmp_path, capsys, monkeypatch):
    from scenegen import export as ex

    def half_then_refuse(d, dest, progress=None):
        (dest / "images").mkdir()
        (dest / "images" / "x.png").write_bytes(b"x")
        raise ex.ExportError("refused for the test")

    monkeypatch.setitem(ex.FORMATS, "nerf", half_then_refuse)
    dest = tmp_path / "out.nerf"
    assert main(["export", str(ds.root), "--format", "nerf", "-o", str(dest)]) == 2
    assert "refused for the test" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []  # neither the destination nor the staging folder
    dest.mkdir()  # an empty destination given by the user is kept as it was
    assert main(["export", str(ds.root), "--format", "nerf", "-o", str(dest)]) == 2
    assert [p.name for p in tmp_path.iterdir()] == ["out.nerf"] and not any(dest.iterdir())
    assert main(["export", str(ds.root), "--format", "nerf", "-o", str(tmp_path / "new/deep/out")]) == 2
    assert [p.name for p in tmp_path.iterdir()] == ["out.nerf"]  # the folders made for it are gone too
    monkeypatch.undo()
    assert main(["export", str(ds.root), "--format", "nerf", "-o", str(dest)]) == 0  # not blocked
    assert (dest / "transforms.json").is_file()


def test_kitti_odometry_layout_read_as_the_devkit_and_evo_read_it(ds, tmp_path):
    """KITTI odometry (devkit readme: calib.txt ``P0..P3``, ``Tr``, 12 numbers each; poses/XX.txt
    world_from_cam0 with the world cam0 at frame 0; times.txt seconds), read here with plain
    numpy and with evo's KITTI reader."""
    dest = run_export(ds, "kitti-odometry", tmp_path)
    seq = dest / "sequences" / "00"
    calib = {}
    for ln in (seq / "calib.txt").read_text().splitlines():
        key, vals = ln.split(":", 1)
        calib[key] = np.array([float(x) for x in vals.split()]).reshape(3, 4)
    assert sorted(calib) == ["P0", "P1", "P2", "P3", "Tr"] and np.array_equal(calib["Tr"], np.eye(4)[:3])
    frames = ds.crossview.stereo_frames()
    c = json.loads(ds.path(stereo_path(frames[0].left_view, "calib")).read_text())
    assert np.array_equal(calib["P0"], calib["P2"]) and np.array_equal(calib["P1"], calib["P3"])
    assert np.allclose(calib["P0"], c["P1"], rtol=1e-12) and np.allclose(calib["P1"], c["P2"], rtol=1e-12)
    f = calib["P0"][0, 0]
    assert abs(-calib["P1"][0, 3] / f - 0.12) < 1e-9  # the rig's 0.12 m baseline
    assert [float(x) for x in (seq / "times.txt").read_text().split()] == [0.0, 1.0]  # static: the frame index
    for k, fr in enumerate(frames):
        for folder, shape in (("image_0", (150, 200)), ("image_1", (150, 200)), ("image_2", (150, 200, 3)),
                              ("image_3", (150, 200, 3))):
            assert cv2.imread(str(seq / folder / f"{k:06d}.png"), cv2.IMREAD_UNCHANGED).shape == shape
    # the poses: the left rectified camera (R1 after the raw pose) relative to frame 0
    rect = []
    for fr in frames:
        cf = json.loads(ds.path(stereo_path(fr.left_view, "calib")).read_text())
        raw = ds.camera(fr.left_view)[1]
        R = np.array(cf["R1"]) @ raw.R
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R.T, -R.T @ (np.array(cf["R1"]) @ raw.t)  # world_from_rect
        rect.append(T)
    want = [np.linalg.inv(rect[0]) @ T for T in rect]
    lines = np.loadtxt(dest / "poses" / "00.txt").reshape(-1, 3, 4)
    assert np.array_equal(lines[0], np.eye(4)[:3]) or np.abs(lines[0] - np.eye(4)[:3]).max() < 1e-15
    assert np.abs(lines - np.array(want)[:, :3]).max() < 1e-12
    evo_traj = file_interface.read_kitti_poses_file(str(dest / "poses" / "00.txt"))
    assert np.abs(evo_traj.positions_xyz - np.array(want)[:, :3, 3]).max() < 1e-12
