"""TUM RGB-D trajectory files (``timestamp tx ty tz qx qy qz qw``), one per camera stream.

A stream is the views of one camera name, rig and rig member, in frame order; its file is
``<rig>_<member>.txt`` for a rig member and ``<camera>.txt`` for a free camera. Each line is the
camera's pose in the world (world_from_cam: t = camera centre, q = its rotation, scalar LAST as
TUM writes it), OpenCV camera axes, metres. Timestamp = the view's time on a sequence's clock
(``time_s``), or, for a static scene (no clock), its frame_index. Quaternions come from :func:`scenegen.geometry.rotation.quat_wxyz_from_matrix`.
"""
from __future__ import annotations

from scenegen.export.common import fmt, name, write
from scenegen.geometry.rotation import quat_wxyz_from_matrix


def export(ds, dest) -> dict:
    streams: dict[str, list] = {}
    for v in ds.views:
        info = ds.view_info(v)
        key = name("stream", f"{info['rig']}_{info['rig_member']}" if info.get("rig") else info["camera_name"])
        streams.setdefault(key, []).append((info.get("time_s", info["frame_index"]), v))
    for key, items in streams.items():
        what = "time_s" if "time_s" in ds.view_info(items[0][1]) else "frame index"
        lines = [f"# scenegen truth: timestamp (= {what}) tx ty tz qx qy qz qw, world_from_cam, OpenCV camera axes"]
        for frame, v in sorted(items):
            _, pose = ds.camera(v)
            wfc = pose.inverse()
            w, x, y, z = quat_wxyz_from_matrix(wfc.R)
            lines.append(" ".join([f"{frame:.6f}"] + [fmt(c) for c in (*wfc.t, x, y, z, w)]))
        write(dest, f"{key}.txt", ("\n".join(lines) + "\n").encode())
    return {"files": len(streams), "streams": sorted(streams)}
