"""A dataset's LiDAR sweeps as the point-cloud files LiDAR tools read, one file per sweep of each
``lidar`` stream (docs/dataset_format.md, "Streams"):

* ``kitti-velodyne``: ``<stream>/velodyne/<sweep:06d>.bin``, KITTI's raw float32 rows
  (x, y, z, reflectance), as the KITTI devkit reads them (``np.fromfile(..., np.float32).reshape(-1, 4)``);
* ``nuscenes-lidar``: ``<stream>/<sweep:06d>.pcd.bin``, nuScenes' float32 rows (x, y, z,
  intensity, ring index) (``LidarPointCloud.from_file`` of the nuScenes devkit);
* ``lidar-pcd``: ``<stream>/<sweep:06d>.pcd``, PCL's PCD v0.7, binary, fields x y z intensity
  ring time range;
* ``lidar-ply``: ``<stream>/<sweep:06d>.ply``, binary little-endian PLY, one vertex per point with
  the same fields.

A point is a beam's measured return (``measured_point_m``: the LiDAR frame at the beam's own time,
the raw, motion-skewed cloud a sensor's driver gives); beams without a return are left out.
``intensity`` / ``reflectance`` is the return model's ``rho cos(incidence) exp(-2 alpha r)`` in
[0, 1] (KITTI's reflectance is in [0, 1] too; nuScenes' recorded intensities are 0-255: scale by
255 to compare); ``ring`` the beam's rank by elevation (0 = lowest); ``time`` (float64, s) the beam's time
after its sweep's first sample; ``range`` the measured range (m).
"""
from __future__ import annotations

import numpy as np

from scenegen.export.common import name, write
from scenegen.export.errors import ExportError

#: (name, numpy dtype, PCD size, PCD type, PLY type) of the PCD / PLY per-point fields.
POINT_FIELDS = (("x", "<f4", 4, "F", "float"), ("y", "<f4", 4, "F", "float"), ("z", "<f4", 4, "F", "float"),
                ("intensity", "<f4", 4, "F", "float"), ("ring", "<u2", 2, "U", "ushort"),
                ("time", "<f8", 8, "F", "double"), ("range", "<f4", 4, "F", "float"))
POINT_DTYPE = np.dtype([(n, t) for n, t, *_ in POINT_FIELDS])


def sweep_points(ds):
    """Yield (stream, sweep index, (n,) POINT_DTYPE points) of every sweep of every lidar stream."""
    streams = ds.streams.of_kind("lidar")
    if not streams:
        raise ExportError(f"{ds.root} has no LiDAR stream (a rig member of kind lidar writes one)")
    for stream in streams:
        s = ds.streams[stream]
        stream_name = name("stream", stream)
        sweeps = s.field("sweep")
        start = s.time_s
        fields = {k: s.field(k) for k in ("measured_point_m", "measured_range_m", "intensity", "ring", "beam_time_s")}
        for k in np.unique(sweeps):
            rows = sweeps == k
            r = fields["measured_range_m"][rows].reshape(-1)
            keep = np.isfinite(r)
            p = fields["measured_point_m"][rows].reshape(-1, 3)[keep]
            out = np.empty(int(keep.sum()), POINT_DTYPE)
            out["x"], out["y"], out["z"] = p[:, 0], p[:, 1], p[:, 2]
            out["intensity"] = fields["intensity"][rows].reshape(-1)[keep]
            out["ring"] = fields["ring"][rows].reshape(-1)[keep]
            out["time"] = fields["beam_time_s"][rows].reshape(-1)[keep] - start[rows][0]
            out["range"] = r[keep]
            yield stream_name, int(k), out


def encode_kitti_bin(points) -> bytes:
    """KITTI velodyne rows: float32 (x, y, z, reflectance), little-endian, no header."""
    return np.column_stack([points["x"], points["y"], points["z"], points["intensity"]]).astype("<f4").tobytes()


def encode_nuscenes_bin(points) -> bytes:
    """nuScenes ``.pcd.bin`` rows: float32 (x, y, z, intensity, ring index), no header."""
    return np.column_stack([points["x"], points["y"], points["z"], points["intensity"],
                            points["ring"].astype(np.float32)]).astype("<f4").tobytes()


def encode_pcd(points) -> bytes:
    """PCD v0.7 (PCL's point cloud data format), ``DATA binary``: the header, then the points
    as packed little-endian records in field order."""
    n = len(points)
    header = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
              f"FIELDS {' '.join(f[0] for f in POINT_FIELDS)}\nSIZE {' '.join(str(f[2]) for f in POINT_FIELDS)}\n"
              f"TYPE {' '.join(f[3] for f in POINT_FIELDS)}\nCOUNT {' '.join('1' for _ in POINT_FIELDS)}\n"
              f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n")
    return header.encode("ascii") + np.ascontiguousarray(points, POINT_DTYPE).tobytes()


def encode_ply(points) -> bytes:
    """Binary little-endian PLY with one ``vertex`` element of the POINT_FIELDS properties."""
    props = "".join(f"property {f[4]} {f[0]}\n" for f in POINT_FIELDS)
    header = f"ply\nformat binary_little_endian 1.0\nelement vertex {len(points)}\n{props}end_header\n"
    return header.encode("ascii") + np.ascontiguousarray(points, POINT_DTYPE).tobytes()


def _exporter(path_of, encode):
    def export(ds, dest, progress=None) -> dict:
        total = sum(len(np.unique(ds.streams[s].field("sweep"))) for s in ds.streams.of_kind("lidar"))
        files = []
        for stream, k, points in sweep_points(ds):
            files.append(write(dest, path_of(stream, k), encode(points)))
            if progress is not None:
                progress(len(files), total)
        return {"files": len(files), "sweeps": len(files)}
    return export


export_kitti = _exporter(lambda s, k: f"{s}/velodyne/{k:06d}.bin", encode_kitti_bin)
export_nuscenes = _exporter(lambda s, k: f"{s}/{k:06d}.pcd.bin", encode_nuscenes_bin)
export_pcd = _exporter(lambda s, k: f"{s}/{k:06d}.pcd", encode_pcd)
export_ply = _exporter(lambda s, k: f"{s}/{k:06d}.ply", encode_ply)
