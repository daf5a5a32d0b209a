"""Wheel odometry as a sensor kind: the ``wheel_odometry:`` section, a rig member (the robot's
base: x forward, y left, z up) sampling the rig's trajectory at its own rate into a stream of true
and measured wheel speeds of a differential drive and the odometry integrated from the measured
ones, beside the base's true planar pose (docs/scene_spec.md, "Wheel odometry"; the model in
:mod:`scenegen.geometry.wheel_odometry`).

Samples are stamped on the rig's clock every ``1 / rate_hz`` seconds from the view set's first
frame time to its last; the sample stamped ``s`` is taken at ``s + time_offset_s``, where the base
is at ``world_from_rig(t) @ rig_from_sensor``, and only those within the trajectory's keyframes are
written (as the IMU's). The wheels need a velocity at every sample: any trajectory has one
(a ``linear`` one jumps at its keyframes).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset.stream_writer import StreamWriter
from scenegen.dataset.streams import DEFAULT_CHUNK_SAMPLES, StreamField, StreamSchema
from scenegen.errors import SpecError, Where
from scenegen.geometry.clock import Composed, StaticTrajectory
from scenegen.geometry.rotation import quat_wxyz_from_matrix
from scenegen.geometry.wheel_odometry import DiffDrive, integrate_diff_drive, measured_wheel_speeds, wheel_truth
from scenegen.spec.model.meta import SEED_MAX, field_info, param, where_field
from scenegen.spec.parse.fields import check_keys, read_fields, read_value, write_fields
from scenegen.spec.sensors.imu import MAX_IMU_SAMPLES, imu_sample_times
from scenegen.spec.sensors.kind import STREAM, SensorKind, SensorRun


@dataclass(frozen=True, kw_only=True)
class WheelOdometrySpec:
    """A differential drive's wheel encoders under ``wheel_odometry:``."""

    name: str
    rate_hz: float = param(50.0, unit="Hz", lo=0, lo_open=True, hi=100000.0)  # samples per second
    wheel_radius_m: float = param(0.1, unit="m", lo=0, lo_open=True, hi=100.0)
    track_width_m: float = param(0.5, unit="m", lo=0, lo_open=True, hi=100.0)  # between the contact points
    slip_left: float = param(0.0, unit="slip ratio", lo=-0.9, hi=10.0)  # wheel turns (1 + s) x its ground speed
    slip_right: float = param(0.0, unit="slip ratio", lo=-0.9, hi=10.0)
    wheel_speed_noise_rad_s: float = param(0.0, unit="rad/s", lo=0, hi=1000.0)  # white, std per sample
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX, derived="seed32(scene seed, field path)")
    where: Where | None = where_field()

    @property
    def drive(self) -> DiffDrive:
        return DiffDrive(self.wheel_radius_m, self.track_width_m)


def parse_wheel_odometry(node, name, ctx) -> WheelOdometrySpec:
    f = check_keys(node.as_mapping("wheel odometry (rate_hz, wheel_radius_m, track_width_m, slip_left, ...)"),
                   WheelOdometrySpec)
    values = read_fields(f, WheelOdometrySpec)
    values["seed"] = (read_value(f.get("seed"), field_info(WheelOdometrySpec, "seed")) if "seed" in f
                      else ctx.seed_for(node.path))
    return WheelOdometrySpec(name=name, where=node.where, **values)


def wheel_odometry_to_yaml(w: WheelOdometrySpec) -> dict:
    return write_fields(w)


def check_wheel_view_set(member, w: WheelOdometrySpec, vs, node) -> None:
    """2 to MAX_IMU_SAMPLES samples within the rig trajectory's keyframes."""
    tf = node.as_mapping().get("trajectory")
    where = tf if tf is not None else node
    knots = vs.placement.trajectory.trajectory().times_s
    frames = vs.placement.times_s
    count = int(np.floor((max(frames) - min(frames)) * w.rate_hz + 1e-9)) + 1
    if count > MAX_IMU_SAMPLES:
        raise where.error(f"the wheel odometry {member.name!r} would take {count:,} samples at {w.rate_hz:g} Hz; "
                          f"at most {MAX_IMU_SAMPLES:,} per stream")
    stamps, _ = imu_sample_times(frames, member.time_offset_s, w.rate_hz, knots)
    if len(stamps) < 2:
        raise where.error(f"the wheel odometry {member.name!r} samples at {w.rate_hz:g} Hz: fewer than 2 samples "
                          f"fall within the trajectory's keyframes [{knots[0]:g}, {knots[-1]:g}] s")


FIELDS = (
    StreamField("stamp_s", "float64", unit="s", doc="timestamp on the rig clock: time_s - time_offset_s"),
    StreamField("wheel_speed_rad_s", "float64", (2,), "rad/s", "measured [left, right]: true (1 + slip) + noise"),
    StreamField("wheel_speed_true_rad_s", "float64", (2,), "rad/s", "[left, right] of the base's v and yaw rate"),
    StreamField("odom_pose", "float64", (3,), "m, m, rad",
                "x, y, yaw integrated from the measured speeds, odometry frame (the base at the first sample)"),
    StreamField("true_pose", "float64", (3,), "m, m, rad", "the base's true x, y, yaw in the odometry frame"),
    StreamField("velocity_base_mps", "float64", (3,), "m/s", "true velocity in the base's axes (x: the wheels')"),
    StreamField("yaw_rate_rad_s", "float64", unit="rad/s", doc="true angular velocity about the base's z"),
    StreamField("position_m", "float64", (3,), "m", "world_from_base translation"),
    StreamField("quat_wxyz", "float64", (4,), "", "world_from_base rotation, unit quaternion w >= 0"),
)


def write_wheel_odometry(run: SensorRun) -> None:
    """The member's samples (module docstring), in chunks of DEFAULT_CHUNK_SAMPLES."""
    w, member = run.sensor, run.member
    traj = run.spec.view_sets[run.frames[0].view_set].placement.trajectory.trajectory()
    world_from_base = Composed(traj, StaticTrajectory(member.rig_from_sensor))
    stamps, times = imu_sample_times([f.time_s for f in run.frames], member.time_offset_s, w.rate_hz, traj.times_s)
    if len(times) < 2:  # the spec check refuses this; a spec built in Python may not have run it
        raise SpecError.at(w.where, f"the wheel odometry {member.name!r} has fewer than 2 samples within its "
                           "trajectory")
    truth = wheel_truth(world_from_base, times, w.drive)
    measured = measured_wheel_speeds(truth.wheel_speeds_rad_s, w.slip_left, w.slip_right, w.wheel_speed_noise_rad_s,
                                     w.seed, run.stream)
    fields = {
        "stamp_s": stamps, "wheel_speed_rad_s": measured, "wheel_speed_true_rad_s": truth.wheel_speeds_rad_s,
        "odom_pose": integrate_diff_drive(measured, times, w.drive), "true_pose": truth.planar_pose,
        "velocity_base_mps": truth.velocity_base_mps, "yaw_rate_rad_s": truth.yaw_rate_rad_s,
        "position_m": truth.t, "quat_wxyz": np.stack([quat_wxyz_from_matrix(R) for R in truth.R])}
    sw = StreamWriter(run.writer, run.stream, StreamSchema("wheel_odometry", member.sensor, FIELDS))
    for k, start in enumerate(range(0, len(times), DEFAULT_CHUNK_SAMPLES)):
        part = slice(start, start + DEFAULT_CHUNK_SAMPLES)
        sw.write_chunk(k, times[part], {name: a[part] for name, a in fields.items()})
    sw.close()


WHEEL_ODOMETRY = SensorKind(name="wheel_odometry", section="wheel_odometry", model=WheelOdometrySpec,
                            parse=parse_wheel_odometry, produces=STREAM, truth=tuple(f.name for f in FIELDS),
                            write=write_wheel_odometry, to_yaml=wheel_odometry_to_yaml,
                            check_view_set=check_wheel_view_set)
