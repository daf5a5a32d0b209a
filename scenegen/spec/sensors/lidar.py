"""The LiDAR as a sensor kind: the ``lidars:`` section, a rig member that sweeps once per frame of
its view set, every beam cast at its own firing time, into a stream of per-beam truth and
measurements (docs/scene_spec.md, "LiDARs"; docs/dataset_format.md, "Streams"; the scan patterns
and the return model in :mod:`scenegen.geometry.lidar`, the sweep in :mod:`.lidar_sweep`).

Sweep ``k`` starts at frame ``k``'s time plus the member's ``time_offset_s``; it must end before
the next frame's sweep starts (a stream's times increase). A stream sample is one column of a
spinning head (one line of a raster), its fields hold the sample's ``C`` beams.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from scenegen.dataset.stream_writer import StreamWriter
from scenegen.dataset.streams import StreamField, StreamSchema
from scenegen.errors import SpecError, Where
from scenegen.geometry.clock import Composed, StaticTrajectory
from scenegen.geometry.lidar import RETURN_MODES, ScanPattern, raster_pattern, spinning_pattern
from scenegen.geometry.lidar_presets import LIDAR_PRESETS
from scenegen.spec.model.meta import SEED_MAX, field_info, frozen_mapping, param, where_field
from scenegen.spec.parse.fields import check_keys, read_fields, read_value, write_fields
from scenegen.spec.sensors.kind import STREAM, SensorKind, SensorRun
from scenegen.spec.sensors.lidar_sweep import sweep_fields

#: The most beams one LiDAR stream may hold, footprint rays counted (a sweep is cast at once).
MAX_LIDAR_RAYS = 50_000_000
PATTERNS = ("spinning", "raster")
_FROM_PRESET = "the preset's value"
_PRESET_KEYS = ("pattern", "elevations_deg", "azimuth_offsets_deg", "firing_offsets_us", "columns", "rate_hz",
                "clockwise", "min_range_m", "max_range_m")


@dataclass(frozen=True, kw_only=True)
class LidarSpec:
    """A LiDAR under ``lidars:`` (module docstring; :mod:`scenegen.geometry.lidar`)."""

    name: str
    preset: str | None = param(None, unit="LiDAR preset", choices=tuple(LIDAR_PRESETS),
                               doc_default="none; a preset's values are the defaults of the pattern keys not given")
    pattern: str = param("spinning", unit="scan pattern", choices=PATTERNS, derived=_FROM_PRESET + ", else spinning")
    elevations_deg: tuple[float, ...] | None = param(
        None, unit="degrees", lo=-90, hi=90, derived=_FROM_PRESET,
        doc_default="required for a spinning pattern without a preset: one per channel")
    azimuth_offsets_deg: tuple[float, ...] | None = param(None, unit="degrees", derived="0 per channel",
                                                          doc_default="0 per channel")
    firing_offsets_us: tuple[float, ...] | None = param(None, unit="us", lo=0, derived="0 per channel",
                                                        doc_default="0 per channel (all fire at the column's start)")
    columns: int = param(1024, unit="samples per sweep", lo=1, hi=100000, derived=_FROM_PRESET + ", else 1024")
    rows: int = param(64, unit="raster lines", lo=1, hi=10000)
    fov_h_deg: float = param(120.0, unit="degrees", lo=0, lo_open=True, hi=180)
    fov_v_deg: float = param(25.0, unit="degrees", lo=0, hi=180)
    rate_hz: float = param(10.0, unit="Hz", lo=0, lo_open=True, hi=1000.0, derived=_FROM_PRESET + ", else 10")
    clockwise: bool = param(True, unit="spin seen from above", derived=_FROM_PRESET + ", else true")
    start_azimuth_deg: float = param(0.0, unit="degrees", lo=-360, hi=360)
    min_range_m: float = param(0.5, unit="m", lo=0, derived=_FROM_PRESET + ", else 0.5")
    max_range_m: float = param(120.0, unit="m", lo=0, lo_open=True, derived=_FROM_PRESET + ", else 120")
    divergence_mrad: float = param(0.0, unit="mrad (full angle)", lo=0, hi=100)
    footprint_rays: int = param(1, unit="rays per beam", lo=1, hi=64)
    return_mode: str = param("strongest", unit="return", choices=RETURN_MODES)
    range_noise_m: float = param(0.0, unit="m (1 sigma)", lo=0, hi=10)
    reflectivity: float = param(0.5, unit="fraction (objects not in object_reflectivity)", lo=0, hi=1)
    attenuation_per_m: float = param(0.0, unit="1/m", lo=0, hi=1)
    min_intensity: float = param(0.0, unit="intensity (below: no return)", lo=0, hi=1)
    max_incidence_deg: float = param(90.0, unit="degrees", lo=0, hi=90)
    dropout_rate: float = param(0.0, unit="probability a return is lost", lo=0, hi=1)
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX, derived="seed32(scene seed, field path)")
    object_reflectivity: object = field(default_factory=frozen_mapping)  # object name -> reflectivity
    where: Where | None = where_field()

    def scan_pattern(self) -> ScanPattern:
        """The sweep this LiDAR makes (:mod:`scenegen.geometry.lidar`)."""
        if self.pattern == "raster":
            return raster_pattern(fov_h_deg=self.fov_h_deg, fov_v_deg=self.fov_v_deg, rows=self.rows,
                                  columns=self.columns, rate_hz=self.rate_hz)
        n = len(self.elevations_deg)
        return spinning_pattern(elevations_deg=self.elevations_deg,
                                azimuth_offsets_deg=self.azimuth_offsets_deg or (0.0,) * n,
                                firing_offsets_s=np.asarray(self.firing_offsets_us or (0.0,) * n) * 1e-6,
                                columns=self.columns, rate_hz=self.rate_hz, clockwise=self.clockwise,
                                start_azimuth_deg=self.start_azimuth_deg)


_DEFAULTS = {f.name: f.default for f in dataclasses.fields(LidarSpec)}


def parse_lidar(node, name, ctx) -> LidarSpec:
    """One entry of ``lidars:``; explicit keys override the preset's values."""
    f = check_keys(node.as_mapping("a LiDAR (preset, pattern, elevations_deg, columns, rate_hz, ...)"), LidarSpec,
                   optional=("object_reflectivity",))
    values = read_fields(f, LidarSpec, skip=("object_reflectivity",))
    base = dict(LIDAR_PRESETS.get(values["preset"], {}))
    if "elevations_deg" in f:  # channels of one's own: the preset's per-channel tables do not apply
        base = {k: v for k, v in base.items() if k not in ("azimuth_offsets_deg", "firing_offsets_us")}
    for key in _PRESET_KEYS:  # derived fields: written, else the preset's, else the default
        values[key] = (read_value(f.get(key), field_info(LidarSpec, key)) if key in f
                       else base.get(key, _DEFAULTS[key]))
    values["seed"] = (read_value(f.get("seed"), field_info(LidarSpec, "seed")) if "seed" in f
                      else ctx.seed_for(node.path))
    refl = {}
    if "object_reflectivity" in f:
        rf = f.get("object_reflectivity").as_mapping("object name -> reflectivity in [0, 1]")
        for key in rf.keys():  # the names are checked against the objects when the sweep is cast
            refl[key] = rf.value(key).as_float("reflectivity", lo=0, hi=1)
    lidar = LidarSpec(name=name, where=node.where, object_reflectivity=frozen_mapping(refl), **values)
    check_pattern(lidar, f, node)
    return lidar


def check_pattern(lidar: LidarSpec, f, node) -> None:
    """The rules across fields: a spinning pattern's channel tables agree in length, its firing
    offsets lie within a column, ranges are ordered."""
    at = lambda key: f.get(key) if key in f else node  # noqa: E731
    if lidar.min_range_m >= lidar.max_range_m:
        raise at("min_range_m").error(f"expected min_range_m < max_range_m ({lidar.max_range_m:g} m), "
                                      f"got {lidar.min_range_m:g} m")
    if lidar.pattern != "spinning":
        return
    if lidar.elevations_deg is None:
        raise node.error("a spinning LiDAR needs elevations_deg (one per channel) or a preset "
                         f"({', '.join(LIDAR_PRESETS)})")
    n = len(lidar.elevations_deg)
    for key in ("azimuth_offsets_deg", "firing_offsets_us"):
        values = getattr(lidar, key)
        if values is not None and len(values) != n:
            raise at(key).error(f"expected {n} values (one per channel of elevations_deg), got {len(values)}")
    period_us = 1e6 / (lidar.columns * lidar.rate_hz)
    if lidar.firing_offsets_us is not None and max(lidar.firing_offsets_us) >= period_us:
        raise at("firing_offsets_us").error(
            f"every firing offset must be below one column's {period_us:.6g} us ({lidar.columns} columns at "
            f"{lidar.rate_hz:g} Hz), got {max(lidar.firing_offsets_us):g} us")


def lidar_to_yaml(lidar: LidarSpec) -> dict:
    out = write_fields(lidar)
    if lidar.object_reflectivity:
        out["object_reflectivity"] = dict(lidar.object_reflectivity)
    return out


def check_lidar_view_set(member, lidar: LidarSpec, vs, node) -> None:
    """Sweeps must not overlap (frames at least one sweep apart) and the stream stays within
    MAX_LIDAR_RAYS rays."""
    times = np.sort(np.asarray(vs.placement.times_s, np.float64))
    gaps = np.diff(times)
    sweep_s = 1.0 / lidar.rate_hz
    if len(gaps) and gaps.min() < sweep_s - 1e-12:
        raise node.error(f"the LiDAR {member.name!r} sweeps for {sweep_s:g} s ({lidar.rate_hz:g} Hz) from each frame, "
                         f"but frames are {gaps.min():g} s apart: sweeps would overlap; lower fps or raise rate_hz")
    rays = len(times) * int(np.prod(_pattern_shape(lidar))) * lidar.footprint_rays
    if rays > MAX_LIDAR_RAYS:
        raise node.error(f"the LiDAR {member.name!r} would cast {rays:,} rays over {len(times)} frames; "
                         f"at most {MAX_LIDAR_RAYS:,} per stream")


def _pattern_shape(lidar: LidarSpec) -> tuple[int, int]:
    if lidar.pattern == "raster":
        return lidar.rows, lidar.columns
    return lidar.columns, len(lidar.elevations_deg)


#: (name, dtype, per-sample shape with "C" for the beams of a sample, unit, meaning) of each field.
FIELDS = (
    ("sweep", "uint32", (), "", "the sweep (frame) this sample belongs to"),
    ("column", "uint32", (), "", "the sample's index in its sweep (a column, a raster line)"),
    ("channel", "uint16", ("C",), "", "each beam's laser index in the preset's table"),
    ("ring", "uint16", ("C",), "", "each beam's rank by elevation, 0 = lowest"),
    ("beam_time_s", "float64", ("C",), "s", "each beam's firing time on the clock"),
    ("azimuth_rad", "float64", ("C",), "rad", "beam azimuth, LiDAR frame, ccw from +x"),
    ("elevation_rad", "float64", ("C",), "rad", "beam elevation, LiDAR frame"),
    ("range_m", "float64", ("C",), "m", "true range of the beam's axis to the first surface; inf: none"),
    ("point_sensor_m", "float64", ("C", 3), "m", "true hit, LiDAR frame at the beam's time; NaN: none"),
    ("point_world_m", "float64", ("C", 3), "m", "true hit, world frame; NaN: none"),
    ("object_id", "uint32", ("C",), "", "object id of the surface hit; 0: none"),
    ("instance_id", "uint32", ("C",), "", "instance id of the surface hit; 0: none"),
    ("incidence_rad", "float64", ("C",), "rad", "angle between the beam and the surface normal; NaN: none"),
    ("sensor_position_m", "float64", ("C", 3), "m", "world_from_lidar translation at the beam's time"),
    ("sensor_quat_wxyz", "float64", ("C", 4), "", "world_from_lidar rotation at the beam's time"),
    ("returns_m", "float64", ("C", 3), "m", "first, strongest, last return ranges (noise-free); inf: none"),
    ("intensity", "float32", ("C",), "", "rho cos(incidence) exp(-2 alpha r) of the selected return"),
    ("measured_range_m", "float64", ("C",), "m", "the selected return plus range noise; NaN: no return"),
    ("measured_point_m", "float64", ("C", 3), "m", "measured_range_m along the beam, LiDAR frame"),
    ("dropped", "bool", ("C",), "", "the axis hit a surface in range but the beam gave no return"),
)


def schema_fields(beams: int) -> tuple[StreamField, ...]:
    """FIELDS with the per-sample beam count ``beams`` in place of "C"."""
    return tuple(StreamField(name, dtype, tuple(beams if n == "C" else n for n in shape), unit, doc)
                 for name, dtype, shape, unit, doc in FIELDS)


def lidar_trajectory(run: SensorRun, frame):
    """world_from_lidar over time: the view set's trajectory (or the frame's still pose) with
    the member's ``rig_from_sensor``."""
    traj_spec = run.spec.view_sets[frame.view_set].placement.trajectory
    rig = traj_spec.trajectory() if traj_spec is not None else StaticTrajectory(frame.world_from_rig)
    return Composed(rig, StaticTrajectory(run.member.rig_from_sensor))


def write_lidar(run: SensorRun) -> None:
    """One chunk per sweep (module docstring)."""
    lidar, member = run.sensor, run.member
    if run.scene is None:
        raise SpecError.at(lidar.where, f"the LiDAR {member.name!r} needs a loaded scene to cast its beams")
    pattern = lidar.scan_pattern()
    ids = {o.name: o.object_id for o in run.spec.objects}
    unknown = sorted(set(lidar.object_reflectivity) - set(ids))
    if unknown:
        raise SpecError.at(lidar.where, f"object_reflectivity names no object {unknown[0]!r}; objects: "
                           f"{', '.join(ids) or 'none'}")
    reflectivity = {ids[name]: v for name, v in lidar.object_reflectivity.items()}
    sw = StreamWriter(run.writer, run.stream, StreamSchema("lidar", member.sensor, schema_fields(pattern.shape[1])))
    for k, frame in enumerate(run.frames):
        t0 = frame.time_s + member.time_offset_s
        fields = sweep_fields(run.scene.cast_beams, lidar, pattern, lidar_trajectory(run, frame), t0,
                              reflectivity=reflectivity, noise_key=(lidar.seed, run.stream, k))
        fields["sweep"] = np.full(pattern.shape[0], k, np.uint32)
        sw.write_chunk(k, t0 + pattern.sample_time_s, fields)
    sw.close()


LIDAR = SensorKind(name="lidar", section="lidars", model=LidarSpec, parse=parse_lidar, produces=STREAM,
                   truth=tuple(f[0] for f in FIELDS), write=write_lidar, to_yaml=lidar_to_yaml,
                   check_view_set=check_lidar_view_set)
