"""Exports of a dataset folder into other tools' formats, one module per format.

``export(out_dir, fmt, dest)`` reads a dataset (:class:`scenegen.dataset.reader.Dataset`; its cross-view
files where a format needs them) and writes ``dest`` (a new or empty folder). Nothing here
imports Mitsuba. Formats (docs/crossview.md, "Exports"):

* ``colmap``: COLMAP text model (cameras.txt, images.txt, points3D.txt) + images/;
* ``gaussian-splatting``: 3DGS scene folder (undistorted PINHOLE images/, sparse/0/);
* ``nerf``: instant-ngp / nerfstudio ``transforms.json`` + images/, depth/, masks/, a split;
* ``kitti-stereo``: KITTI 2015 stereo layout from the rectified stereo frames (calib, obj_map);
* ``kitti-odometry``: KITTI odometry layout (image_0..3, calib.txt, times.txt, poses/00.txt) from
  one rig's rectified stereo frames;
* ``middlebury``: MiddEval3 folders (im0/im1.png, disp0GT/disp1GT.pfm, mask0nocc.png, calib.txt);
* ``opencv``: cv2.FileStorage YAML (K, D, R, T per view; K1 D1 K2 D2 R T E F R1 R2 P1 P2 Q per
  stereo frame; R T E F per cross-view pair);
* ``tum``: TUM RGB-D trajectories and per stream rgb/, depth/ (x5000), rgb.txt, depth.txt,
  groundtruth.txt, associations.txt, camera.txt and orbslam.yaml (intrinsics and distortion).
* ``tapvid``: TAP-Vid point tracks (video, normalised points, occlusion), one NPZ per stream;
* ``tracks-video``: a GIF and an MP4 per stream of a sequence with its point tracks drawn;
* ``kitti-flow``: KITTI 2015 flow layout (flow_occ / flow_noc PNGs) from a sequence's flow;
* ``kitti-sceneflow``: KITTI 2015 scene flow layout (disp_*_0, disp_*_1, flow_* on the rectified
  left grid, obj_map, calib) from a stereo rig's sequence;
* ``sintel``: MPI-Sintel layout (final/, flow/, occlusions/, invalid/, depth/, camdata_left/) per
  camera stream of a sequence of pinhole cameras;
* ``euroc``: EuRoC MAV ``mav0/`` (camN images and data.csv, imu0, state_groundtruth_estimate0,
  sensor.yaml files) plus Kalibr's camchain.yaml and imu.yaml, from a rig of cameras and an IMU;
* ``kitti-velodyne``, ``nuscenes-lidar``, ``lidar-pcd``, ``lidar-ply``: a LiDAR stream's sweeps as
  KITTI ``.bin``, nuScenes ``.pcd.bin``, PCD and PLY point clouds (:mod:`.lidar`).
* ``tof``: a ToF stream's raw frames as 16-bit PNG and float32 EXR (with its truth) and its
  calibration JSON (intrinsics, frequencies, phase offsets, extrinsic, poses).
* ``bop``: BOP's scenewise layout (scene_gt, scene_gt_info, scene_camera, rgb/, depth/, mask/,
  mask_visib/, models/ with models_info.json, in mm) from the object truth;
* ``coco``: COCO instances and keypoints (annotations.json: RLE masks, boxes, keypoints with
  visibility, categories with skeletons) + images/, from the object truth.
"""
from __future__ import annotations

from pathlib import Path

from scenegen.export import (
    bop,
    coco,
    colmap,
    euroc,
    gaussian_splatting,
    kitti_flow,
    kitti_odometry,
    kitti_sceneflow,
    kitti_stereo,
    lidar,
    middlebury,
    nerf,
    opencv_yaml,
    sintel,
    tapvid,
    tof,
    tracks_video,
    tum,
)
from scenegen.export.common import open_dataset, staged_dest
from scenegen.export.errors import ExportError

#: Format name -> its exporter ``export(dataset, dest, progress=None) -> summary dict``
#: (``progress(done, total)`` after each view, stereo frame, reference view or stream).
FORMATS = {"colmap": colmap.export, "gaussian-splatting": gaussian_splatting.export, "nerf": nerf.export,
           "kitti-stereo": kitti_stereo.export, "middlebury": middlebury.export, "opencv": opencv_yaml.export,
           "tum": tum.export, "tapvid": tapvid.export, "tracks-video": tracks_video.export,
           "kitti-flow": kitti_flow.export, "kitti-sceneflow": kitti_sceneflow.export, "sintel": sintel.export,
           "euroc": euroc.export, "kitti-velodyne": lidar.export_kitti, "nuscenes-lidar": lidar.export_nuscenes,
           "lidar-pcd": lidar.export_pcd, "lidar-ply": lidar.export_ply,
           "kitti-odometry": kitti_odometry.export, "tof": tof.export, "bop": bop.export,
           "coco": coco.export}
#: What each exporter's progress counts.
PROGRESS_UNITS = {"colmap": "reference views", "gaussian-splatting": "views", "nerf": "views",
                  "kitti-stereo": "stereo frames", "middlebury": "stereo frames", "opencv": "views", "tum": "views",
                  "tapvid": "streams", "tracks-video": "streams", "kitti-flow": "frame pairs",
                  "kitti-sceneflow": "stereo frame pairs", "sintel": "views",
                  "euroc": "views", "kitti-velodyne": "sweeps", "nuscenes-lidar": "sweeps", "lidar-pcd": "sweeps",
                  "lidar-ply": "sweeps", "kitti-odometry": "stereo frames", "tof": "streams", "bop": "views", "coco": "views"}


def default_dest(out_dir, fmt: str) -> Path:
    """``<OUT>.<format>`` next to the dataset (inside it, ``verify`` would flag the files)."""
    p = Path(out_dir)
    return p.parent / f"{p.name}.{fmt}"


def export(out_dir, fmt: str, dest=None, progress=None) -> dict:
    """Export dataset ``out_dir`` as ``fmt`` into ``dest`` (default :func:`default_dest`);
    returns a summary dict ``{"dest": ..., "files": n, ...}``; ``progress(done, total)``
    is called as the exporter goes (views, stereo frames or reference views)."""
    if fmt not in FORMATS:
        raise ExportError(f"unknown export format {fmt!r}; choose one of {', '.join(FORMATS)}")
    ds = open_dataset(out_dir)
    dest = Path(dest) if dest is not None else default_dest(out_dir, fmt)
    with staged_dest(dest) as stage:  # a refused export leaves no folder behind
        summary = FORMATS[fmt](ds, stage, progress)
    summary["dest"] = str(dest)
    return summary
