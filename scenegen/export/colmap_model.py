"""A COLMAP text model (cameras.txt, images.txt, points3D.txt) from truth, for any per-view camera.

Shared by the ``colmap`` export (the views' own cameras, distortion included) and the
``gaussian-splatting`` export (undistorted PINHOLE cameras):

* Cameras: one COLMAP camera per physical camera: views of the same camera name (a rig member
  is one camera) with identical intrinsics share one CAMERA_ID (``Camera.to_colmap``; COLMAP's
  principal point is OpenCV's + 0.5, see :mod:`scenegen.geometry.conventions`).
* ``images.txt``: ``cam_from_world`` as (qw, qx, qy, qz, tx, ty, tz), image name = ``<view>.png``.
* Tracks: for every cross-view correspondence file i -> j of the dataset, the pixels of i on a
  grid of stride ``STRIDE_PX`` that are VISIBLE in at least one j become 3D points (the truth
  point of i, as stored, float32 widened to float64); the point is observed in i and in every j
  where it is VISIBLE and its projection through the model's camera is finite. Each observation
  is that exact projection (reprojection errors are 0 up to float64), in COLMAP pixels. The same
  surface point seen from two reference views is two COLMAP points (truth is per pixel).
* Without cross-view truth (a spec with no ``crossview:`` section), every view is a reference
  view with no partner: its grid pixels with a surface become points observed in that view only
  (track length 1; what a 3DGS initialisation needs, exact but with no multi-view constraint).
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset import DatasetError
from scenegen.dataset.crossview import VISIBLE
from scenegen.dataset.truth import TruthKind
from scenegen.export.common import each, fmt, write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8
from scenegen.geometry.conventions import colmap_from_opencv_pixels, colmap_pose, in_image

STRIDE_PX = 8
HEAD = "# written by scenegen export (truth; pixels in COLMAP's convention)\n"


def camera_ids(ds, cams: dict) -> tuple[dict[str, int], list[str]]:
    """(view -> CAMERA_ID, cameras.txt lines): one id per (camera name, COLMAP model, size, params)."""
    ids: dict[tuple, int] = {}
    of_view, lines = {}, []
    for v, cam in cams.items():
        model, params = cam.to_colmap()
        key = (ds.view_info(v)["camera_name"], model, cam.width, cam.height, tuple(float(p) for p in params))
        if key not in ids:
            ids[key] = len(ids) + 1
            lines.append(f"{ids[key]} {model} {cam.width} {cam.height} " + " ".join(fmt(p) for p in params))
        of_view[v] = ids[key]
    return of_view, lines


def _links(index, vid) -> dict[str, list[str]]:
    links: dict[str, list[str]] = {}
    for a, b in index.pairs:
        for i, j in ((a, b), (b, a)):
            if i in vid and j in vid:
                links.setdefault(i, []).append(j)
    return links


def tracks(ds, cams: dict, poses: dict, vid: dict, progress=None) -> tuple[dict[str, list], list[str]]:
    """(view -> [(COLMAP uv, point id)], points3D.txt lines) of the truth tracks (module docstring)."""
    try:
        index = ds.crossview.index  # None: no cross-view truth, single-view tracks
    except DatasetError as e:
        raise ExportError(str(e)) from None
    links = _links(index, vid) if index is not None else {v: [] for v in cams}
    min_track = 2 if index is not None else 1
    obs: dict[str, list] = {v: [] for v in cams}
    pt_lines, point_id = [], 0
    for i, others in each(links.items(), progress):
        truth = ds.truth(i)
        image = to_uint8(ds.image(i))
        H, W = truth[TruthKind.VALID].shape
        gv, gu = np.meshgrid(np.arange(0, H, STRIDE_PX), np.arange(0, W, STRIDE_PX), indexing="ij")
        gv, gu = gv.ravel(), gu.ravel()
        vis = {j: ds.crossview.correspondence(i, j).state[gv, gu] == VISIBLE for j in others}
        seen_elsewhere = np.any(np.stack(list(vis.values())), axis=0) if vis else np.ones(gv.shape, bool)
        any_vis = seen_elsewhere & truth[TruthKind.VALID][gv, gu]
        for k in np.flatnonzero(any_vis):
            X = truth[TruthKind.POINTS_WORLD][gv[k], gu[k]].astype(np.float64)
            seen = []
            for view in [i] + [j for j in others if vis[j][k]]:
                uv = cams[view].project(poses[view].apply(X[None]))[0]
                if in_image(uv[None], cams[view].width, cams[view].height)[0]:  # NaN is outside
                    seen.append((view, uv))
            if len(seen) < min_track:
                continue
            point_id += 1
            track = []
            for view, uv in seen:
                obs[view].append((colmap_from_opencv_pixels(uv), point_id))
                track.append((vid[view], len(obs[view]) - 1))
            rgb = np.broadcast_to(np.asarray(image[gv[k], gu[k]]).astype(int), (3,))
            pt_lines.append(f"{point_id} {fmt(X[0])} {fmt(X[1])} {fmt(X[2])} {rgb[0]} {rgb[1]} {rgb[2]} 0 "
                            + " ".join(f"{a} {b}" for a, b in track))
    return obs, pt_lines


def write_model(ds, dest, folder: str, cams: dict, poses: dict, progress=None) -> dict:
    """Write ``dest/folder/{cameras,images,points3D}.txt`` for the views of ``cams`` (view ->
    Camera, view -> cam_from_world); returns counts; ``progress(done, total)`` per reference view."""
    vid = {v: k + 1 for k, v in enumerate(cams)}
    cam_of_view, cam_lines = camera_ids(ds, cams)
    obs, pt_lines = tracks(ds, cams, poses, vid, progress)
    img_lines = []
    for v in cams:
        q, t = colmap_pose(poses[v])
        img_lines.append(f"{vid[v]} " + " ".join(fmt(x) for x in (*q, *t)) + f" {cam_of_view[v]} {v}.png")
        img_lines.append(" ".join(f"{fmt(uv[0])} {fmt(uv[1])} {pid}" for uv, pid in obs[v]))
    pre = f"{folder}/" if folder else ""
    write(dest, pre + "cameras.txt", (HEAD + "# CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]\n" + "\n".join(cam_lines) + "\n").encode())
    img_head = "# IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\n# POINTS2D[] as (X, Y, POINT3D_ID)\n"
    write(dest, pre + "images.txt", (HEAD + img_head + "\n".join(img_lines) + "\n").encode())
    pt_head = "# POINT3D_ID X Y Z R G B ERROR TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
    write(dest, pre + "points3D.txt", (HEAD + pt_head + "\n".join(pt_lines) + ("\n" if pt_lines else "")).encode())
    return {"cameras": len(cam_lines), "images": len(cams), "points3D": len(pt_lines)}
