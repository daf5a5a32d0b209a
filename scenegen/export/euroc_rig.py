"""The visual-inertial rig an EuRoC MAV export writes (:mod:`scenegen.export.euroc`): the dataset's
one IMU stream, the camera members of its rig in member order, their extrinsics relative to the
IMU (the body frame ``B`` of EuRoC, ``imu`` of Kalibr) and their frame timestamps in integer
nanoseconds of the scene clock (its ``t = 0`` is the epoch).

All of it comes from the dataset: the stream (``Dataset.streams``), the views' cameras.json
entries and the resolved spec's ``rigs`` and ``sensors.imu`` (docs/dataset_format.md, "Streams").
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.export.common import name
from scenegen.export.errors import ExportError
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3

NS_PER_S = 1_000_000_000
_IMU_HELP = "a multi rig with camera members and an IMU member (docs/scene_spec.md, \"IMUs\")"


def ns(time_s) -> np.ndarray:
    """(N,) int64 nanoseconds of times in seconds on the scene clock (rounded to the nearest ns)."""
    return np.rint(np.asarray(time_s, np.float64) * NS_PER_S).astype(np.int64)


@dataclass(frozen=True)
class CameraStream:
    """One camera member: ``camera`` (its model), ``imu_from_cam`` (EuRoC's T_BS), its complete
    views in time order and their timestamps (ns)."""

    member: str
    camera: Camera
    imu_from_cam: Rigid3
    views: tuple[str, ...]
    stamps_ns: tuple[int, ...]


@dataclass(frozen=True)
class VioRig:
    """The IMU stream ``stream`` (a :class:`scenegen.dataset.Stream`), its resolved spec values
    ``imu`` (rate_hz and Kalibr's four noise values), its member's ``time_offset_s`` and the rig's
    cameras."""

    rig: str
    stream: object
    imu: dict
    time_offset_s: float
    cameras: tuple[CameraStream, ...]


def _pose(member: dict, key: str, where: str) -> Rigid3:
    try:
        return Rigid3.from_dict(member[key])
    except (KeyError, TypeError, ValueError):
        raise ExportError(f"{where}: expected {key} (R, t) in the resolved spec's rig member") from None


def _imu_stream(ds):
    imus = ds.streams.of_kind("imu")
    if not imus:
        raise ExportError(f"{ds.root} has no IMU stream; the EuRoC layout needs {_IMU_HELP}")
    if len(imus) > 1:
        raise ExportError(f"{ds.root} has {len(imus)} IMU streams ({', '.join(imus)}); the EuRoC layout holds one")
    return ds.streams[imus[0]]


def _find_rig(ds, stream_name: str):
    """(view set prefix, rig name, rig spec dict, IMU member dict) of the IMU stream's rig."""
    rigs = (ds.spec or {}).get("rigs") or {}
    for prefix, rig in sorted({(ds.view_info(v).get("view_set"), ds.view_info(v).get("rig")) for v in ds.views
                               if ds.view_info(v).get("rig") is not None}, key=str):
        for m in (rigs.get(rig) or {}).get("members") or []:
            if m.get("kind") == "imu" and f"{prefix}_{m.get('name')}" == stream_name:
                return prefix, rig, rigs[rig], m
    raise ExportError(f"{ds.root}: the IMU stream {stream_name!r} has no complete camera views in its rig; "
                      f"the EuRoC layout needs {_IMU_HELP}")


def vio_rig(ds) -> VioRig:
    """The dataset's IMU rig (module docstring), or an ExportError saying what it lacks."""
    stream = _imu_stream(ds)
    prefix, rig, rig_spec, imu_member = _find_rig(ds, stream.name)
    where = f"{ds.root}/cameras.json spec.rigs.{rig}"
    rig_from_imu = _pose(imu_member, "rig_from_sensor", where)
    imu = ((ds.spec.get("sensors") or {}).get("imu") or {}).get(stream.sensor)
    if not isinstance(imu, dict) or "rate_hz" not in imu:
        raise ExportError(f"{ds.root}/cameras.json: no spec.sensors.imu.{stream.sensor} (rate_hz, noise values)")
    views = [v for v in ds.views if ds.view_info(v).get("view_set") == prefix and ds.view_info(v).get("rig") == rig]
    cameras = []
    for m in rig_spec.get("members") or []:
        if m.get("kind", "camera") != "camera":
            continue
        mine = sorted((ds.view_info(v)["time_s"], v) for v in views if ds.view_info(v).get("rig_member") == m["name"])
        if not mine:
            continue
        stamps = ns([t for t, _ in mine])
        if stamps[0] < 0 or len(set(stamps.tolist())) != len(stamps):
            raise ExportError(f"{where}: member {m['name']!r} has negative or repeated frame times; EuRoC stamps "
                              "each image with a distinct unsigned nanosecond timestamp")
        rig_from_cam = _pose(m, "rig_from_cam" if "rig_from_cam" in m else "rig_from_sensor", where)
        cameras.append(CameraStream(name("rig member", m["name"]), ds.camera(mine[0][1])[0],
                                    rig_from_imu.inverse() @ rig_from_cam, tuple(v for _, v in mine),
                                    tuple(int(s) for s in stamps)))
    if not cameras:
        raise ExportError(f"{where}: the IMU's rig has no complete camera views; the EuRoC layout needs {_IMU_HELP}")
    return VioRig(rig, stream, imu, float(imu_member.get("time_offset_s", 0.0)), tuple(cameras))
