"""A tiny scenegen dataset with analytic truth, written by scenegen's own DatasetWriter.

Scene: the plane z = 0 (a 6 m x 6 m square mesh of two triangles, textured as a checkerboard in the
images). Views, 40 x 30 px:

* ``left_000`` and ``right_000``: a rectified stereo rig ("stereo"), identical pinhole cameras
  (fx = fy = 40, principal point at the image centre) 3 m above the plane looking straight down,
  the right one displaced by BASELINE_M along the left camera's +x axis;
* ``free_000``: an OpenCV camera with distortion, oblique, looking at the origin.

Truth per pixel centre = the camera model's own ray intersected with z = 0 (exact up to float32
storage)."""
from __future__ import annotations

import numpy as np
import trimesh

from scenegen import dataset as ds
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3, look_at

W, H = 40, 30
BASELINE_M = 0.5
HEIGHT_M = 3.0
PINHOLE = Camera("pinhole", W, H, 40.0, 40.0, (W - 1) / 2, (H - 1) / 2)
DISTORTED = Camera("opencv", W, H, 42.0, 41.0, 19.0, 15.0, 0.0, (-0.05, 0.01, 0.001, -0.001, 0.0))
DOWN = np.diag([1.0, -1.0, -1.0])  # cam_from_world rotation of a camera looking down -z, image x = world x


def view_cameras() -> dict:
    left = Rigid3(DOWN, -DOWN @ np.array([0.0, 0.0, HEIGHT_M]))
    right = Rigid3(DOWN, -DOWN @ np.array([BASELINE_M, 0.0, HEIGHT_M]))
    free = look_at((1.0, -1.5, 2.5), (0.2, 0.1, 0.0)).inverse()
    return {
        "left_000": ds.ViewCamera(PINHOLE, left, "left", rig="stereo", rig_member="left", frame_index=0),
        "right_000": ds.ViewCamera(PINHOLE, right, "right", rig="stereo", rig_member="right", frame_index=0),
        "free_000": ds.ViewCamera(DISTORTED, free, "free", frame_index=0),
    }


def plane_truth(cam: Camera, pose: Rigid3) -> dict:
    uv = np.stack(np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float)), -1).reshape(-1, 2)
    d_cam = cam.unproject_unit(uv)
    world_from_cam = pose.inverse()
    c = world_from_cam.t
    d = d_cam @ world_from_cam.R.T
    s = -c[2] / d[:, 2]
    P = c + s[:, None] * d
    Pc = pose.apply(P)
    valid = (s > 0) & np.all(np.abs(P[:, :2]) < 3.0, axis=1)
    f = lambda a: a.reshape(H, W, *a.shape[1:]).astype(np.float32)  # noqa: E731
    t = {"depth_z": f(Pc[:, 2]), "range": f(s), "points_world": f(P), "points_cam": f(Pc),
         "normals_world": f(np.tile([0.0, 0.0, 1.0], (len(P), 1))), "normals_cam": f(np.tile(pose.R[:, 2], (len(P), 1))),
         "uv": f(np.zeros((len(P), 2))), "object_id": np.ones((H, W), np.uint32),
         "instance_id": np.ones((H, W), np.uint32), "valid": valid.reshape(H, W)}
    miss = ~t["valid"]
    for k in ("depth_z", "range"):
        t[k][miss] = np.inf
    for k in ("points_world", "points_cam", "normals_world", "normals_cam", "uv"):
        t[k][miss] = np.nan
    t["object_id"][miss] = 0
    t["instance_id"][miss] = 0
    return t


def checker_image(truth: dict) -> np.ndarray:
    P = np.nan_to_num(truth["points_world"])
    g = ((np.floor(P[..., 0] / 0.25) + np.floor(P[..., 1] / 0.25)) % 2) * 150 + 60
    g[~truth["valid"]] = 0
    return np.repeat(g[..., None], 3, axis=2).astype(np.uint8)


def write_plane_dataset(root) -> dict:
    """Write the dataset at ``root``; return {view: (Camera, cam_from_world)}."""
    w = ds.DatasetWriter(root, spec_sha256="cd" * 32, seed=1, variant="test", versions={"numpy": "x"})
    vcs = view_cameras()
    w.write_cameras(vcs, {"objects": [{"name": "plane"}]})
    w.write_mesh("plane", trimesh.Trimesh([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], [[0, 1, 2], [0, 2, 3]],
                                          process=False))
    for name, vc in vcs.items():
        t = plane_truth(vc.camera, vc.cam_from_world)
        img = checker_image(t)
        w.write_view(name, image=img, linear_rgb=img.astype(np.float32) / 255, truth=t)
    return {n: (vc.camera, vc.cam_from_world) for n, vc in vcs.items()}
