"""COLMAP text model: cameras.txt, images.txt, points3D.txt (+ images/), tracks from truth.

* One COLMAP camera per view (``Camera.to_colmap``: PINHOLE / OPENCV / FULL_OPENCV /
  OPENCV_FISHEYE; COLMAP's principal point is OpenCV's + 0.5, see :mod:`scenegen.geometry.conventions`).
* ``images.txt``: ``cam_from_world`` as (qw, qx, qy, qz, tx, ty, tz), image name = ``<view>.png``.
* Tracks: for every cross-view correspondence file i -> j of the dataset, the pixels of i on a
  grid of stride ``STRIDE_PX`` that are VISIBLE in at least one j become 3D points (the truth
  point of i, as stored, float32 widened to float64); the point is observed in i and in every j
  where it is VISIBLE. Each observation is the exact projection of the written 3D point through
  the view's camera model (so reprojection errors are 0 up to float64), in COLMAP pixels.
  The same surface point seen from two reference views is two COLMAP points (truth is per pixel).
"""
from __future__ import annotations


import numpy as np

from scenegen.dataset.files import copy_file
from scenegen.dataset.crossview import VISIBLE
from scenegen.dataset.layout import view_paths
from scenegen.export.common import crossview_index, fmt, write
from scenegen.geometry.color import to_uint8
from scenegen.geometry.conventions import colmap_from_opencv_pixels, colmap_pose

STRIDE_PX = 8


def export(ds, dest) -> dict:
    index = crossview_index(ds)
    views = list(ds.views)
    vid = {v: k + 1 for k, v in enumerate(views)}
    cams, poses = {}, {}
    cam_lines, img_lines, pt_lines = [], [], []
    for v in views:
        cam, pose = ds.camera(v)
        cams[v], poses[v] = cam, pose
        model, params = cam.to_colmap()
        cam_lines.append(f"{vid[v]} {model} {cam.width} {cam.height} " + " ".join(fmt(p) for p in params))
    # visible-in lists per reference view
    links: dict[str, list[str]] = {}
    for a, b in index.pairs:
        for i, j in ((a, b), (b, a)):
            if i in vid and j in vid:
                links.setdefault(i, []).append(j)
    obs: dict[str, list] = {v: [] for v in views}  # view -> [(u, v, point_id)]
    point_id = 0
    for i, others in links.items():
        truth = ds.truth(i)
        image = to_uint8(ds.image(i))
        H, W = truth["valid"].shape
        gv, gu = np.meshgrid(np.arange(0, H, STRIDE_PX), np.arange(0, W, STRIDE_PX), indexing="ij")
        gv, gu = gv.ravel(), gu.ravel()
        vis = {}
        for j in others:
            vis[j] = ds.crossview.correspondence(i, j).state[gv, gu] == VISIBLE
        any_vis = np.any(np.stack(list(vis.values())), axis=0) & truth["valid"][gv, gu]
        for k in np.flatnonzero(any_vis):
            X = truth["points_world"][gv[k], gu[k]].astype(np.float64)
            seen = []
            for view in [i] + [j for j in others if vis[j][k]]:
                uv = cams[view].project(poses[view].apply(X[None]))[0]
                if np.all(np.isfinite(uv)):
                    seen.append((view, uv))
            if len(seen) < 2:
                continue
            point_id += 1
            track = []
            for view, uv in seen:
                obs[view].append((colmap_from_opencv_pixels(uv), point_id))
                track.append((vid[view], len(obs[view]) - 1))
            rgb = np.broadcast_to(np.asarray(image[gv[k], gu[k]]).astype(int), (3,))
            pt_lines.append(f"{point_id} {fmt(X[0])} {fmt(X[1])} {fmt(X[2])} {rgb[0]} {rgb[1]} {rgb[2]} 0 "
                            + " ".join(f"{a} {b}" for a, b in track))
    for v in views:
        q, t = colmap_pose(poses[v])
        img_lines.append(f"{vid[v]} " + " ".join(fmt(x) for x in (*q, *t)) + f" {vid[v]} {v}.png")
        img_lines.append(" ".join(f"{fmt(uv[0])} {fmt(uv[1])} {pid}" for uv, pid in obs[v]))
        (dest / "images").mkdir(exist_ok=True)
        copy_file(ds.path(view_paths(v)["image"]), dest / "images" / f"{v}.png")
    head = "# written by scenegen export (truth; pixels in COLMAP's convention)\n"
    write(dest, "cameras.txt", (head + "# CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]\n" + "\n".join(cam_lines) + "\n").encode())
    write(dest, "images.txt", (head + "# IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\n# POINTS2D[] as (X, Y, POINT3D_ID)\n"
                               + "\n".join(img_lines) + "\n").encode())
    write(dest, "points3D.txt", (head + "# POINT3D_ID X Y Z R G B ERROR TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
                                 + "\n".join(pt_lines) + ("\n" if pt_lines else "")).encode())
    return {"files": 3 + len(views), "images": len(views), "points3D": point_id}
