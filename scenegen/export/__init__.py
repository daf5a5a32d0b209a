"""Exports of a dataset folder into other tools' formats, one module per format.

``export(out_dir, fmt, dest)`` reads a dataset (:class:`scenegen.dataset.reader.Dataset`; its cross-view
files where a format needs them) and writes ``dest`` (a new or empty folder). Nothing here
imports Mitsuba. Formats (docs/crossview.md, "Exports"):

* ``colmap``: COLMAP text model (cameras.txt, images.txt, points3D.txt) + images/;
* ``nerf``: instant-ngp / nerfstudio ``transforms.json`` + images/;
* ``kitti-stereo``: KITTI 2015 stereo layout from the rectified stereo frames;
* ``middlebury``: Middlebury v3 folders (im0/im1.png, disp0/disp1.pfm, calib.txt);
* ``opencv``: cv2.FileStorage YAML (K, D, R, T per view; K1 D1 K2 D2 R T E F R1 R2 P1 P2 Q per
  stereo frame; R T E F per cross-view pair);
* ``tum``: TUM RGB-D trajectories, one file per camera stream;
* ``tapvid``: TAP-Vid point tracks (video, normalised points, occlusion), one NPZ per stream;
* ``preview``: a GIF and an MP4 per stream of a sequence with its point tracks drawn;
* ``kitti-flow``: KITTI 2015 flow layout (flow_occ / flow_noc PNGs) from a sequence's flow.
"""
from __future__ import annotations

from pathlib import Path

from scenegen.export import colmap, kitti_flow, kitti_stereo, middlebury, nerf, opencv_yaml, preview, tapvid, tum
from scenegen.export.common import open_dataset, prepare_dest
from scenegen.export.errors import ExportError

#: Format name -> its exporter ``export(dataset, dest) -> summary dict``.
FORMATS = {"colmap": colmap.export, "nerf": nerf.export, "kitti-stereo": kitti_stereo.export,
           "middlebury": middlebury.export, "opencv": opencv_yaml.export, "tum": tum.export,
           "tapvid": tapvid.export, "preview": preview.export,
           "kitti-flow": kitti_flow.export}


def default_dest(out_dir, fmt: str) -> Path:
    """``<OUT>.<format>`` next to the dataset (inside it, ``verify`` would flag the files)."""
    p = Path(out_dir)
    return p.parent / f"{p.name}.{fmt}"


def export(out_dir, fmt: str, dest=None) -> dict:
    """Export dataset ``out_dir`` as ``fmt`` into ``dest`` (default :func:`default_dest`);
    returns a summary dict ``{"dest": ..., "files": n, ...}``."""
    if fmt not in FORMATS:
        raise ExportError(f"unknown export format {fmt!r}; choose one of {', '.join(FORMATS)}")
    ds = open_dataset(out_dir)
    dest = Path(dest) if dest is not None else default_dest(out_dir, fmt)
    prepare_dest(dest)
    summary = FORMATS[fmt](ds, dest)
    summary["dest"] = str(dest)
    return summary
