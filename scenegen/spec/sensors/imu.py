"""The IMU as a sensor kind: the ``imus:`` section, a rig member sampling the rig's trajectory at
its own rate into a stream of true and measured accelerometer and gyroscope readings
(docs/scene_spec.md, "IMUs"; docs/dataset_format.md, "Streams"; the maths in
:mod:`scenegen.geometry.imu`).

Its samples are stamped on the rig's clock every ``1 / rate_hz`` seconds from the view set's first
frame time to its last; the sample stamped ``s`` is taken at the true time ``s + time_offset_s``
(the member's offset: the IMU's clock is behind the rig's by it), where the IMU is at
``world_from_rig(t) @ rig_from_sensor``. Only samples whose true time lies within the
trajectory's keyframes are written (outside them the rig holds its pose: not C2), and the
trajectory must be the C2 ``spline`` (a ``linear`` one has infinite acceleration at keyframes).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from scenegen.dataset.stream_writer import StreamWriter
from scenegen.dataset.streams import DEFAULT_CHUNK_SAMPLES, StreamField, StreamSchema
from scenegen.errors import SpecError, Where
from scenegen.geometry.clock import Composed, StaticTrajectory
from scenegen.geometry.imu import NOISE_PRESETS, ImuNoiseParams, imu_noise, imu_truth, sample_times_s
from scenegen.geometry.rotation import quat_wxyz_from_matrix
from scenegen.spec.model.meta import SEED_MAX, field_info, param, where_field
from scenegen.spec.parse.fields import check_keys, read_fields, read_value, write_fields
from scenegen.spec.sensors.kind import STREAM, SensorKind, SensorRun

#: The most samples one IMU stream may hold (its noise is drawn at once: 12 float64 a sample).
MAX_IMU_SAMPLES = 1_000_000
_NOISE_KEYS = tuple(f.name for f in dataclasses.fields(ImuNoiseParams))
_FROM_PRESET = "the preset's value, else 0"


@dataclass(frozen=True, kw_only=True)
class ImuSpec:
    """An IMU under ``imus:``: its rate and Kalibr's noise values (continuous time)."""

    name: str
    rate_hz: float = param(200.0, unit="Hz", lo=0, lo_open=True, hi=100000.0)  # samples per second
    preset: str | None = param(None, unit="IMU noise preset", choices=tuple(NOISE_PRESETS),
                               doc_default="none (noise-free unless values are given); a preset's "
                                           "values are the defaults of the noise keys not given")
    accelerometer_noise_density: float = param(0.0, unit="m/s^2/sqrt(Hz)", lo=0, derived=_FROM_PRESET)
    accelerometer_random_walk: float = param(0.0, unit="m/s^3/sqrt(Hz)", lo=0, derived=_FROM_PRESET)
    gyroscope_noise_density: float = param(0.0, unit="rad/s/sqrt(Hz)", lo=0, derived=_FROM_PRESET)
    gyroscope_random_walk: float = param(0.0, unit="rad/s^2/sqrt(Hz)", lo=0, derived=_FROM_PRESET)
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX, derived="seed32(scene seed, field path)")
    where: Where | None = where_field()

    @property
    def noise(self) -> ImuNoiseParams:
        return ImuNoiseParams(**{k: getattr(self, k) for k in _NOISE_KEYS})


def parse_imu(node, name, ctx) -> ImuSpec:
    """One entry of ``imus:``; explicit noise keys override the preset's values."""
    f = check_keys(node.as_mapping("an IMU (rate_hz, preset, accelerometer_noise_density, ...)"), ImuSpec)
    values = read_fields(f, ImuSpec)
    base = NOISE_PRESETS[values["preset"]] if values["preset"] is not None else ImuNoiseParams()
    for key in _NOISE_KEYS:
        values[key] = read_value(f.get(key), field_info(ImuSpec, key)) if key in f else getattr(base, key)
    values["seed"] = (read_value(f.get("seed"), field_info(ImuSpec, "seed")) if "seed" in f
                      else ctx.seed_for(node.path))
    return ImuSpec(name=name, where=node.where, **values)


def imu_to_yaml(imu: ImuSpec) -> dict:
    return write_fields(imu)


def imu_sample_times(frame_times_s, time_offset_s: float, rate_hz: float, knot_times_s
                     ) -> tuple[np.ndarray, np.ndarray]:
    """((N,) stamps on the rig's clock, (N,) true times) of an IMU over its view set's frames
    (module docstring): stamps every 1 / rate_hz s from the first frame time to the last, true
    times = stamps + time_offset_s, those within [knot_times_s[0], knot_times_s[-1]] kept."""
    stamps = sample_times_s(float(min(frame_times_s)), float(max(frame_times_s)), rate_hz)
    times = stamps + time_offset_s
    keep = (times >= knot_times_s[0]) & (times <= knot_times_s[-1])
    return stamps[keep], times[keep]


def check_imu_view_set(member, imu: ImuSpec, vs, node) -> None:
    """The rig's trajectory must be C2 (``interpolation: spline``) and give the IMU 2 to
    MAX_IMU_SAMPLES samples within its keyframes."""
    traj = vs.placement.trajectory
    tf = node.as_mapping().get("trajectory")
    where = tf if tf is not None else node
    if traj.interpolation != "spline":
        at = tf.as_mapping().get("interpolation") if tf is not None and "interpolation" in tf.as_mapping() else where
        raise at.error(f"rig {vs.rig!r} holds the IMU {member.name!r}, which needs a C2 trajectory: interpolation "
                       f"{traj.interpolation!r} has infinite acceleration at its keyframes; use interpolation: spline")
    knots = traj.trajectory().times_s
    frames = vs.placement.times_s
    count = int(np.floor((max(frames) - min(frames)) * imu.rate_hz + 1e-9)) + 1
    if count > MAX_IMU_SAMPLES:
        raise where.error(f"the IMU {member.name!r} would take {count:,} samples at {imu.rate_hz:g} Hz over the "
                          f"frames' {max(frames) - min(frames):g} s; at most {MAX_IMU_SAMPLES:,} per stream")
    stamps, _ = imu_sample_times(frames, member.time_offset_s, imu.rate_hz, knots)
    if len(stamps) < 2:
        raise where.error(f"the IMU {member.name!r} samples at {imu.rate_hz:g} Hz from the first frame to the last "
                          f"plus its time_offset_s {member.time_offset_s:g} s: fewer than 2 samples fall within "
                          f"the trajectory's keyframes [{knots[0]:g}, {knots[-1]:g}] s")


FIELDS = (
    StreamField("stamp_s", "float64", unit="s", doc="the IMU's timestamp on the rig clock: time_s - time_offset_s"),
    StreamField("accel_mps2", "float64", (3,), "m/s^2", "measured specific force, IMU frame: true + bias + white"),
    StreamField("gyro_rad_s", "float64", (3,), "rad/s", "measured angular velocity, IMU frame: true + bias + white"),
    StreamField("accel_true_mps2", "float64", (3,), "m/s^2", "true specific force R^T (a - g), IMU frame"),
    StreamField("gyro_true_rad_s", "float64", (3,), "rad/s", "true angular velocity R^T omega, IMU frame"),
    StreamField("accel_bias_mps2", "float64", (3,), "m/s^2", "the accelerometer bias in the measurement"),
    StreamField("gyro_bias_rad_s", "float64", (3,), "rad/s", "the gyroscope bias in the measurement"),
    StreamField("position_m", "float64", (3,), "m", "world_from_imu translation (the IMU origin, world)"),
    StreamField("quat_wxyz", "float64", (4,), "", "world_from_imu rotation, unit quaternion w >= 0"),
    StreamField("velocity_mps", "float64", (3,), "m/s", "velocity of the IMU origin, world frame"),
)


def write_imu(run: SensorRun) -> None:
    """The member's samples (module docstring), in chunks of DEFAULT_CHUNK_SAMPLES."""
    imu, member = run.sensor, run.member
    traj_spec = run.spec.view_sets[run.frames[0].view_set].placement.trajectory
    if traj_spec.interpolation != "spline":  # the spec check refuses this; a spec built in Python may not have run it
        raise SpecError.at(traj_spec.where, f"the IMU {member.name!r} needs a C2 trajectory (interpolation: spline), "
                           f"got {traj_spec.interpolation!r}")
    traj = traj_spec.trajectory()
    world_from_imu = Composed(traj, StaticTrajectory(member.rig_from_sensor))
    stamps, times = imu_sample_times([f.time_s for f in run.frames], member.time_offset_s, imu.rate_hz,
                                     traj.times_s)
    if len(times) < 2:  # the spec check refuses this; a spec built in Python may not have run it
        raise SpecError.at(imu.where, f"the IMU {member.name!r} has fewer than 2 samples within its trajectory")
    truth = imu_truth(world_from_imu, times)
    noise = imu_noise(imu.noise, len(times), 1.0 / imu.rate_hz, imu.seed, run.stream)
    fields = {
        "stamp_s": stamps,
        "accel_mps2": truth.specific_force_mps2 + noise.accel_bias_mps2 + noise.accel_white_mps2,
        "gyro_rad_s": truth.angular_velocity_rad_s + noise.gyro_bias_rad_s + noise.gyro_white_rad_s,
        "accel_true_mps2": truth.specific_force_mps2, "gyro_true_rad_s": truth.angular_velocity_rad_s,
        "accel_bias_mps2": noise.accel_bias_mps2, "gyro_bias_rad_s": noise.gyro_bias_rad_s,
        "position_m": truth.t, "quat_wxyz": np.stack([quat_wxyz_from_matrix(R) for R in truth.R]),
        "velocity_mps": truth.velocity_mps}
    sw = StreamWriter(run.writer, run.stream, StreamSchema("imu", member.sensor, FIELDS))
    for k, start in enumerate(range(0, len(times), DEFAULT_CHUNK_SAMPLES)):
        part = slice(start, start + DEFAULT_CHUNK_SAMPLES)
        sw.write_chunk(k, times[part], {name: a[part] for name, a in fields.items()})
    sw.close()


IMU = SensorKind(name="imu", section="imus", model=ImuSpec, parse=parse_imu, produces=STREAM,
                 truth=tuple(f.name for f in FIELDS), write=write_imu, to_yaml=imu_to_yaml,
                 check_view_set=check_imu_view_set)
