"""The time-of-flight (AMCW) depth camera as a sensor kind: the ``tof_cameras:`` section, a rig
member whose frames are written as a stream (docs/scene_spec.md, "ToF cameras";
docs/dataset_format.md, "Streams"; the phase convention in :mod:`scenegen.geometry.tof`, the
rendering in :mod:`scenegen.render.tof`, the pixel model in :mod:`scenegen.imaging.tof`).

A stream, not a views kind: its output per frame is four raw correlation frames per frequency
and truth of its own (direct-path range, multipath error, wrap counts, flying-pixel label), not
an RGB image with the camera's truth set, and it samples at its own time offset in the rig (a
Kinect's depth and colour exposures are not simultaneous). So the pipeline's view path is
unchanged; the frames are timestamped samples of shape (H, W, ...) in the stream's chunks, one
frame a chunk, hashed, resumable and verified like every stream.

The intrinsics are a camera of ``cameras:`` (``camera: NAME``; its model, size and distortion);
the sensor frame is that camera's OpenCV frame, posed ``world_from_rig(t) @ rig_from_sensor``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset.stream_writer import StreamWriter
from scenegen.dataset.streams import StreamField, StreamSchema
from scenegen.dataset.truth_kinds import TruthKind
from scenegen.errors import Where
from scenegen.geometry import tof as g
from scenegen.geometry.seeds import seed32
from scenegen.imaging.noise import SensorParams
from scenegen.imaging.tof import TofPixelParams, decode, expose, truth_errors, valid_mask
from scenegen.spec.model.meta import SEED_MAX, field_info, param, where_field
from scenegen.spec.parse.fields import check_keys, read_fields, read_value, write_fields
from scenegen.spec.sensors.kind import STREAM, SensorKind, SensorRun

MHZ = 1e6


@dataclass(frozen=True, kw_only=True)
class TofSpec:
    """A ToF camera under ``tof_cameras:`` (module docstring; the pixel model's values)."""

    name: str
    camera: str = param(unit="a camera of cameras: (the intrinsics)")
    frequency_mhz: float = param(80.0, unit="MHz", lo=0, lo_open=True, hi=2000.0)  # modulation frequency
    frequency2_mhz: float | None = param(None, unit="MHz", lo=0, lo_open=True, hi=2000.0,
                                         doc_default="none (one frequency: the wrapped range)")
    max_range_m: float | None = param(None, unit="m", lo=0, lo_open=True,
                                      doc_default="the frequency pair's unambiguous range c / (2 gcd(f1, f2))")
    spp: int = param(16, unit="rays per pixel", lo=1, hi=1024)
    max_bounces: int = param(3, unit="surface vertices of a path", lo=1, hi=16)
    pixel_centre_rays: bool = param(False, unit="flag")  # every ray through its pixel's centre: no mixed returns
    integration_s: float = param(1e-3, unit="s", lo=0, lo_open=True, hi=10.0)  # each tap's exposure
    signal_e_per_s_at_1m: float = param(2e6, unit="e-/s", lo=0)  # tap offset, white Lambertian facing at 1 m
    ambient_e_per_s: float = param(0.0, unit="e-/s", lo=0)  # unmodulated background per tap
    contrast: float = param(1.0, unit="modulation contrast", lo=0, lo_open=True, hi=1.0)
    noise: bool = param(True, unit="flag")  # shot and read noise drawn (False: their means)
    read_noise_e: float = param(3.0, unit="e-", lo=0)
    gain_dn_per_e: float = param(1.0, unit="DN/e-", lo=0, lo_open=True, hi=1000.0)
    full_well_e: float = param(60000.0, unit="e-", lo=1)
    adc_bits: int = param(16, unit="bits", lo=1, hi=16)
    min_amplitude_e: float = param(20.0, unit="e-", lo=0)  # a valid pixel's smallest amplitude
    flying_threshold_m: float = param(0.05, unit="m", lo=0, lo_open=True)  # a flying pixel's mixing error
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX, derived="seed32(scene seed, field path)")
    where: Where | None = where_field()

    @property
    def freqs_hz(self) -> tuple[float, ...]:
        """The modulation frequencies in Hz (a pair: whole hertz, as the parser checked)."""
        if self.frequency2_mhz is None:
            return (self.frequency_mhz * MHZ,)
        return (float(round(self.frequency_mhz * MHZ)), float(round(self.frequency2_mhz * MHZ)))

    def pixel(self) -> TofPixelParams:
        sensor = SensorParams(system_gain_dn_per_e=self.gain_dn_per_e, dark_noise_e=self.read_noise_e,
                              saturation_capacity_e=self.full_well_e, adc_bits=self.adc_bits,
                              temporal_noise=self.noise)
        return TofPixelParams(freqs_hz=self.freqs_hz, integration_s=self.integration_s,
                              signal_e_per_s_at_1m=self.signal_e_per_s_at_1m, ambient_e_per_s=self.ambient_e_per_s,
                              contrast=self.contrast, min_amplitude_e=self.min_amplitude_e, sensor=sensor)


def parse_tof(node, name, ctx) -> TofSpec:
    """One entry of ``tof_cameras:``; its camera must be in ``cameras:``, a frequency pair whole
    hertz (their gcd is the unwrapping's period)."""
    f = check_keys(node.as_mapping("a ToF camera (camera, frequency_mhz, ...)"), TofSpec)
    values = read_fields(f, TofSpec)
    if values["camera"] not in ctx.cameras:
        known = ", ".join(sorted(ctx.cameras)) or "none"
        raise f.get("camera").error(f"no camera {values['camera']!r} in cameras: (known: {known})")
    if values["frequency2_mhz"] is not None:
        for key in ("frequency_mhz", "frequency2_mhz"):
            hz = values[key] * MHZ
            if abs(hz - round(hz)) > 1e-3:
                raise f.get(key).error(f"a frequency pair must be whole hertz (their gcd sets the unwrapping range), "
                                       f"got {values[key]!r} MHz")
        if values["frequency2_mhz"] == values["frequency_mhz"]:
            raise f.get("frequency2_mhz").error("the second frequency must differ from frequency_mhz")
    values["seed"] = (read_value(f.get("seed"), field_info(TofSpec, "seed")) if "seed" in f
                      else ctx.seed_for(node.path))
    return TofSpec(name=name, where=node.where, **values)


def tof_to_yaml(tof: TofSpec) -> dict:
    return write_fields(tof)


def tof_fields(width: int, height: int, n_freqs: int) -> tuple[StreamField, ...]:
    """The stream's fields for a W x H camera with ``n_freqs`` frequencies (one frame a sample)."""
    hw, hwf = (height, width), (height, width, n_freqs)
    return (
        StreamField("raw_dn", "uint16", hwf + (4,), "DN", "raw correlation frames per frequency at phase "
                    "offsets 0, pi/2, pi, 3pi/2 (scenegen.geometry.tof), as read out"),
        StreamField("raw_mean_e", "float32", hwf + (4,), "e-", "their expected electrons (noise-free)"),
        StreamField("range_m", "float32", hw, "m", "decoded range along the pixel's ray (unwrapped with two "
                    "frequencies, wrapped with one) of raw_dn, or of raw_mean_e with noise off; NaN where not valid"),
        StreamField("depth_m", "float32", hw, "m", "decoded z-depth: range_m times the pixel ray's z"),
        StreamField("amplitude_e", "float32", hwf, "e-", "decoded amplitude per frequency"),
        StreamField("valid", "bool", hw, "", "amplitude >= min_amplitude_e at every frequency, no tap saturated"),
        StreamField("range_true_m", "float32", hw, "m", "truth: direct-path range at the pixel centre (inf: no surface)"),
        StreamField("depth_true_m", "float32", hw, "m", "truth: its z-depth (inf: no surface)"),
        StreamField("wrap_count", "int32", hwf, "", "truth: floor(range / (c / 2f)) per frequency (-1: no surface)"),
        StreamField("multipath_error_m", "float32", hw, "m", "truth: noise-free decoding of all paths minus "
                    "that of the direct light (NaN: no direct light)"),
        StreamField("mixing_error_m", "float32", hw, "m", "truth: noise-free decoding of the direct light minus "
                    "range_true_m (a flying pixel's error; NaN: no direct light or no surface at the centre)"),
        StreamField("flying", "bool", hw, "", "truth: a mixed return: the pixel has direct light but its centre "
                    "sees no surface, or |mixing_error_m| > flying_threshold_m"),
        StreamField("incidence_deg", "float32", hw, "deg", "truth: angle between the ray and the surface "
                    "normal at the centre hit (NaN: none)"),
        StreamField("world_from_sensor", "float64", (4, 4), "m", "the sensor's pose at the sample time"),
    )


TOF_FIELD_NAMES = tuple(f.name for f in tof_fields(1, 1, 1))


def tof_frame(scene, tof: TofSpec, cam_from_world, time_s: float, frame_seed: int) -> dict[str, np.ndarray]:
    """One frame's field values (:func:`tof_fields`) in ``scene`` (a LoadedScene)."""
    camera = scene.cameras[tof.camera]
    p = tof.pixel()
    sums = scene.tof(camera, cam_from_world, p.freqs_hz, spp=tof.spp, seed=seed32(frame_seed, "rays"),
                     max_bounces=tof.max_bounces, centre=tof.pixel_centre_rays, time_s=time_s)
    truth = scene.truth(camera, cam_from_world, time_s=time_s)
    frames = expose(sums, p, seed=seed32(frame_seed, "noise"))
    # noise off: the expectation is decoded (no shot, read or quantisation noise); raw_dn stays the ADC's
    rng, amp, _ = decode(frames.dn if tof.noise else frames.mean_e * p.gain_dn_per_e, p, tof.max_range_m)
    valid = valid_mask(amp, frames.saturated, p)
    rays = np.asarray(scene.camera_rays(camera)).reshape(camera.height, camera.width, 3)
    r_true = np.asarray(truth[TruthKind.RANGE], np.float64)
    multipath, mixing = truth_errors(sums, r_true, p, tof.max_range_m)
    n = np.asarray(truth[TruthKind.NORMALS_CAM], np.float64)
    cos_inc = np.abs(np.sum(n * rays, axis=-1))
    return {
        "raw_dn": frames.dn, "raw_mean_e": frames.mean_e,
        "range_m": np.where(valid, rng, np.nan), "depth_m": np.where(valid, rng * rays[..., 2], np.nan),
        "amplitude_e": amp, "valid": valid,
        "range_true_m": r_true, "depth_true_m": truth[TruthKind.DEPTH_Z],
        "wrap_count": np.stack([g.wrap_count(r_true, f) for f in p.freqs_hz], axis=-1).astype(np.int32),
        "multipath_error_m": multipath, "mixing_error_m": mixing,
        "flying": (sums["direct_dc"] > 0) & (~np.isfinite(r_true) | (np.abs(np.nan_to_num(mixing)) > tof.flying_threshold_m)),
        "incidence_deg": np.degrees(np.arccos(np.clip(cos_inc, 0.0, 1.0))),
        "world_from_sensor": cam_from_world.inverse().matrix,
    }


def write_tof(run: SensorRun) -> None:
    """One frame per rig frame at the member's sample time, one chunk each, in time order."""
    tof, member = run.sensor, run.member
    camera = run.scene.cameras[tof.camera]
    schema = StreamSchema("tof", member.sensor, tof_fields(camera.width, camera.height, len(tof.freqs_hz)))
    sw = StreamWriter(run.writer, run.stream, schema)
    for k, (frame, t) in enumerate(zip(run.frames, run.sample_times_s())):
        world_from_sensor = frame.world_from_rig @ member.rig_from_sensor
        values = tof_frame(run.scene, tof, world_from_sensor.inverse(), t, seed32(tof.seed, frame.frame_index))
        sw.write_chunk(k, np.array([t]), {name: v[None] for name, v in values.items()})
    sw.close()


TOF = SensorKind(name="tof", section="tof_cameras", model=TofSpec, parse=parse_tof, produces=STREAM,
                 truth=TOF_FIELD_NAMES, write=write_tof, to_yaml=tof_to_yaml)
