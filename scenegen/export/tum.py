"""TUM RGB-D: trajectory files (``timestamp tx ty tz qx qy qz qw``), one per camera stream, and
per stream a folder in the TUM RGB-D dataset's layout.

A stream is the views of one camera name, rig and rig member, in frame order; its name is
``<rig>_<member>`` for a rig member and ``<camera>`` for a free camera.

* ``<stream>.txt``: each line is the camera's pose in the world (world_from_cam: t = camera
  centre, q = its rotation, scalar LAST as TUM writes it), OpenCV camera axes, metres.
  Timestamp = the view's time on a sequence's clock (``time_s``, seconds, ``%.6f``), or, for a
  static scene (no clock), its frame_index. Quaternions come from
  :func:`scenegen.geometry.rotation.quat_wxyz_from_matrix`.
* ``<stream>/``: ``rgb/<timestamp>.png`` (8-bit RGB), ``depth/<timestamp>.png`` (uint16 z-depth
  times 5000, TUM's factor: 5000 = 1 m; 0 = no surface or beyond 13.107 m), ``rgb.txt`` and
  ``depth.txt`` (``timestamp filename``), ``groundtruth.txt`` (the trajectory above) and
  ``associations.txt`` (``timestamp rgb/... timestamp depth/...``, what TUM's associate.py gives;
  depth and colour share their timestamps exactly); ``camera.txt`` and ``orbslam.yaml``, the
  camera's intrinsics and distortion (:mod:`scenegen.export.tum_calib`).
"""
from __future__ import annotations

from scenegen.dataset.codecs import encode_png
from scenegen.dataset.truth import TruthKind
from scenegen.export.common import depth_png16, fmt, name, write
from scenegen.export.tum_calib import calibration_files
from scenegen.geometry.color import to_uint8
from scenegen.geometry.rotation import quat_wxyz_from_matrix

DEPTH_UNITS_PER_M = 5000.0
TRAJECTORY_HEAD = "# scenegen truth: timestamp (= {what}) tx ty tz qx qy qz qw, world_from_cam, OpenCV camera axes"


def _list(kind: str, rows) -> bytes:
    return (f"# {kind}\n# timestamp filename\n" + "".join(f"{ts} {f}\n" for ts, f in rows)).encode()


def export(ds, dest, progress=None) -> dict:
    streams: dict[str, list] = {}
    for v in ds.views:
        info = ds.view_info(v)
        key = name("stream", f"{info['rig']}_{info['rig_member']}" if info.get("rig") else info["camera_name"])
        streams.setdefault(key, []).append((info.get("time_s", info["frame_index"]), v))
    n, too_far = 0, 0
    done = 0
    calibration: dict[str, str] = {}
    for key, items in streams.items():
        what = "time_s" if "time_s" in ds.view_info(items[0][1]) else "frame index"
        lines, rgb, depth = [TRAJECTORY_HEAD.format(what=what)], [], []
        for frame, v in sorted(items):
            _, pose = ds.camera(v)
            wfc = pose.inverse()
            w, x, y, z = quat_wxyz_from_matrix(wfc.R)
            ts = f"{frame:.6f}"
            lines.append(" ".join([ts] + [fmt(c) for c in (*wfc.t, x, y, z, w)]))
            truth = ds.truth(v)
            d16, far = depth_png16(truth[TruthKind.DEPTH_Z], truth[TruthKind.VALID], DEPTH_UNITS_PER_M)
            too_far += far
            rgb.append((ts, write(dest, f"{key}/rgb/{ts}.png", encode_png(to_uint8(ds.image(v))))[len(key) + 1:]))
            depth.append((ts, write(dest, f"{key}/depth/{ts}.png", encode_png(d16))[len(key) + 1:]))
        traj = ("\n".join(lines) + "\n").encode()
        write(dest, f"{key}.txt", traj)
        write(dest, f"{key}/groundtruth.txt", traj)
        write(dest, f"{key}/rgb.txt", _list("color images", rgb))
        write(dest, f"{key}/depth.txt", _list("depth maps", depth))
        assoc = "".join(f"{a} {fa} {b} {fb}\n" for (a, fa), (b, fb) in zip(rgb, depth))
        write(dest, f"{key}/associations.txt", assoc.encode())
        info = ds.view_info(items[0][1])
        calib = calibration_files(key, info["camera_name"], ds.camera(items[0][1])[0], [f for f, _ in sorted(items)])
        if isinstance(calib, str):
            calibration[key] = f"none: {calib}"
        else:
            for fname, data in calib.items():
                write(dest, f"{key}/{fname}", data)
            calibration[key] = ", ".join(calib)
            n += len(calib)
        n += 5 + 2 * len(items)
        done += len(items)
        if progress is not None:
            progress(done, len(ds.views))
    return {"files": n, "streams": sorted(streams), "depth_beyond_range": too_far, "calibration": calibration}
