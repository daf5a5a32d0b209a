"""The sensor kinds a rig may hold: one entry per kind (docs/architecture.md, "Add a sensor
kind"). The spec reads each kind's section and rig members through it, and the pipeline writes
each member's output through it."""
from __future__ import annotations

from scenegen.spec.sensors.camera import CAMERA
from scenegen.spec.sensors.imu import IMU
from scenegen.spec.sensors.kind import SensorKind
from scenegen.spec.sensors.lidar import LIDAR
from scenegen.spec.sensors.wheel_odometry import WHEEL_ODOMETRY
from scenegen.spec.sensors.tof import TOF
from scenegen.spec.sensors.projector import PROJECTOR

#: Sensor kind name -> SensorKind (a rig member's default kind: RigMember.kind, the camera).
SENSOR_KINDS: dict[str, SensorKind] = {
    CAMERA.name: CAMERA,
    IMU.name: IMU,
    LIDAR.name: LIDAR,
    WHEEL_ODOMETRY.name: WHEEL_ODOMETRY,
    TOF.name: TOF,
    PROJECTOR.name: PROJECTOR,
}


def section_kinds() -> tuple[SensorKind, ...]:
    """The kinds whose sections live in ``SceneSpec.sensors`` (not a SceneSpec field of their own)."""
    return tuple(k for k in SENSOR_KINDS.values() if k.spec_field is None)
