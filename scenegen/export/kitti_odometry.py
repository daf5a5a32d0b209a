"""KITTI odometry layout (the odometry benchmark's ``data_odometry_*`` folders) from the
rectified stereo frames (crossview/stereo/*) of one stereo rig, in frame order.

* ``sequences/00/image_0/{k:06d}.png`` and ``image_1/`` (left and right rectified, 8-bit grey, as
  KITTI's grey pair), ``image_2/`` and ``image_3/`` (the same pair in 8-bit RGB, as its colour
  pair: here the same two cameras);
* ``sequences/00/calib.txt``: ``P0:`` .. ``P3:`` (3x4 row-major rectified projection matrices:
  P0 = P2 the left one, P1 = P3 the right one with ``P[0, 3] = -f B``) and ``Tr:`` (KITTI's
  cam0-from-velodyne; no LiDAR here: the identity), the format pykitti's ``odometry`` reads;
* ``sequences/00/times.txt``: each frame's time in seconds (``%e``), the left view's ``time_s``;
  a dataset without a clock gets the frame index (the summary's ``times`` says which);
* ``poses/00.txt``: 12 numbers per line, the left rectified camera's ``world_from_cam`` with the
  world its frame at frame 0 (line 0 the identity), KITTI's convention, OpenCV axes.

Every frame must share one rectification (``P1``, ``P2``, to rounding): a sequence has one
calib.txt, the first frame's.
"""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.cameras import camera_of
from scenegen.dataset.codecs import encode_png
from scenegen.export.common import each, stereo_frames, write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_grey8, to_uint8
from scenegen.geometry.pose import Rigid3


def _row(M) -> str:
    return " ".join(f"{x:.12e}" for x in np.asarray(M, float).ravel())


def rect_from_world(calib: dict) -> Rigid3:
    """The left rectified camera's cam_from_world: ``R1`` (x_rect = R1 x_raw) after the raw pose."""
    _, raw = camera_of(calib["raw_left"])
    R1 = np.asarray(calib["R1"], float)
    return Rigid3(R1 @ raw.R, R1 @ raw.t)


def _same(P, ref) -> bool:
    """Equal to rounding: each frame's rectification is computed from its own poses, so a rig's
    differs from frame to frame in the last bits (3.6e-15 of 170 on a test rig)."""
    P = np.asarray(P, float)
    return P.shape == ref.shape and bool(np.all(np.abs(P - ref) <= 1e-9 * max(1.0, np.abs(ref).max())))


def export(ds, dest, progress=None) -> dict:
    frames = stereo_frames(ds)
    rigs = {(ds.view_info(f.left_view).get("rig"), ds.view_info(f.left_view).get("view_set")) for f in frames}
    if len(rigs) != 1:
        raise ExportError(f"{ds.root}: stereo frames of {len(rigs)} rigs or view sets; a KITTI odometry sequence "
                          "holds one")
    first = frames[0].calib
    P_left, P_right = np.asarray(first["P1"], float), np.asarray(first["P2"], float)
    times, origin, poses, out = [], None, [], []
    for k, fr in enumerate(each(frames, progress)):
        c = fr.calib
        if not (_same(c["P1"], P_left) and _same(c["P2"], P_right)):
            raise ExportError(f"{ds.root}: stereo frame {fr.left_view!r} is rectified unlike the first; a KITTI "
                              "odometry sequence has one calib.txt")
        tag = f"{k:06d}"
        for side, grey, rgb in (("left", "image_0", "image_2"), ("right", "image_1", "image_3")):
            image = fr.image(side)
            write(dest, f"sequences/00/{grey}/{tag}.png", encode_png(to_grey8(image)))
            write(dest, f"sequences/00/{rgb}/{tag}.png", encode_png(to_uint8(image)))
        info = ds.view_info(fr.left_view)
        times.append(info.get("time_s", info["frame_index"]))
        world_from_rect = rect_from_world(c).inverse()
        origin = origin if origin is not None else world_from_rect.inverse()
        poses.append((origin @ world_from_rect).matrix[:3])
        out.append({"index": tag, "left_view": fr.left_view, "right_view": fr.right_view})
    calib = "".join(f"P{i}: {_row(P)}\n" for i, P in enumerate((P_left, P_right, P_left, P_right)))
    write(dest, "sequences/00/calib.txt", (calib + f"Tr: {_row(np.eye(4)[:3])}\n").encode())
    write(dest, "sequences/00/times.txt", "".join(f"{float(t):e}\n" for t in times).encode())
    write(dest, "poses/00.txt", "".join(_row(T) + "\n" for T in poses).encode())
    write(dest, "frames.json", (json.dumps(out, indent=2) + "\n").encode())
    clock = "time_s" if "time_s" in ds.view_info(frames[0].left_view) else "frame index (no clock)"
    return {"files": 4 * len(frames) + 4, "frames": len(frames), "times": clock}
