"""The photometric chain: clean linear radiance -> the image a camera delivers (pure function).

Stage order (each stage's output unit in brackets):

 1. vignetting map   V(u, v) = cos^4(theta) * P(r)                      [unitless, (H, W)]
 2. exposure         mu_p = L * V * t * photons_per_radiance_c          [photons, (H, W, 3)]
                     (camera equation, :mod:`.exposure`)
 3. quantum eff.     mu_e = eta_c * mu_p                                [electrons, (H, W, 3)]
 4. colour filter    Bayer mosaic (optional): one channel per pixel     [electrons, (H, W)]
 5. sensor           PRNU, shot noise, dark current, full well, read
                     noise, DSNU, system gain K, black level, ADC       [DN, uint16]
                     (EMVA 1288, :mod:`.noise`)
 6. demosaic         OpenCV (only with a Bayer mosaic)                  [DN, (H, W, 3)]
 7. normalise        (dn - black) / (white - black)                     [linear, 1 = full scale]
 8. white balance    per-channel gains, clip to [0, 1]                  [linear]
    (colour correction: the identity in this colour model, :mod:`.raw`)
 9. response         sRGB / gamma / linear                              [encoded, [0, 1]]
10. quantise         8 or 16 bit                                        [uint8 / uint16]

Stage 5's output is the raw mosaic (``ImagingResult.raw_dn``, written with ``raw:``); stages
6-10 are the ISP, run as the recorded stage list of :func:`isp_stages` by
:func:`scenegen.imaging.isp.develop`, so the delivered image is a function of the raw one.

Random draws: stage 5 only, seeded per frame (``seed``) and per camera (fixed patterns), see
:mod:`.seeds`. Everything else is deterministic.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from scenegen.imaging import bayer, isp, seeds
from scenegen.imaging.exposure import ExposureParams, photons_per_radiance
from scenegen.imaging.noise import SensorParams, expose_sensor
from scenegen.imaging.raw import RawOutput
from scenegen.imaging.vignetting import VignettingParams, vignetting_map

STAGES = ("vignetting", "exposure", "quantum_efficiency", "bayer_mosaic", "sensor", "demosaic",
          "normalise", "white_balance", "response", "quantise")


@dataclass(frozen=True, kw_only=True)
class ImagingParams:
    preset: str | None = None  # preset the parameters started from (provenance only)
    exposure: ExposureParams = field(default_factory=ExposureParams)
    vignetting: VignettingParams = field(default_factory=VignettingParams)
    sensor: SensorParams = field(default_factory=SensorParams)
    bayer: str | None = None  # CFA pattern (bayer.PATTERNS) or None: every pixel has R, G and B
    demosaic: str = "bilinear"  # bayer.DEMOSAIC_METHODS, used with a Bayer pattern
    white_balance: tuple[float, float, float] | None = None  # gains (R, G, B); None: the gains
    # that make a surface of equal R, G, B radiance neutral (see neutral_white_balance)
    response: str = "srgb"  # response.RESPONSES
    gamma: float = 2.2  # exponent of the 'gamma' response
    bit_depth: int = 8  # output bits per channel: 8 or 16
    raw: RawOutput | None = None  # raw files to write (None: none; the chain is the same)


@dataclass(frozen=True, eq=False)
class ImagingResult:
    image: np.ndarray  # (H, W, 3) uint8 / uint16: the delivered image (the PNG)
    vignetting: np.ndarray  # (H, W) float32: relative illumination V applied (the truth map)
    electrons: np.ndarray  # (H, W, 3), or (H, W) with a Bayer mosaic, float32: collected
    # electrons after full-well clipping, before read noise
    raw_dn: np.ndarray  # like electrons, uint16: ADC output with black level (before demosaic):
    # the raw mosaic, DN below black kept down to 0 unless the sensor clips at black
    record: dict[str, Any]  # JSON-able: parameters, derived constants, ISP stages and seeds used


def electrons_per_radiance(params: ImagingParams) -> np.ndarray:
    """(3,) mean photo-electrons per pixel per unit radiance (W m^-2 sr^-1) over the exposure,
    on the axis: eta_c * photons_per_radiance_c * t."""
    s = params.sensor
    ppr = [photons_per_radiance(params.exposure, s.pixel_pitch_um, w) for w in s.wavelengths_nm]
    return np.asarray(s.quantum_efficiency) * np.asarray(ppr) * params.exposure.exposure_time_s


def neutral_white_balance(params: ImagingParams) -> tuple[float, float, float]:
    """Gains (R, G, B), G = 1, that make equal-radiance R, G, B come out equal."""
    e = electrons_per_radiance(params)
    return tuple(float(e[1] / c) for c in e)


def white_balance_gains(params: ImagingParams) -> tuple[float, float, float]:
    """The white-balance gains (R, G, B) the chain applies: the given ones or the neutral ones."""
    return params.white_balance if params.white_balance is not None else neutral_white_balance(params)


def isp_stages(params: ImagingParams) -> list[dict[str, Any]]:
    """Stages 6-10 as the JSON-able list :func:`scenegen.imaging.isp.develop` runs (and
    cameras.json records): raw DN -> the delivered image."""
    s = params.sensor
    stages = [] if params.bayer is None else [isp.demosaic_stage(params.bayer, params.demosaic)]
    return stages + [isp.normalise_stage(s.black_level_dn, s.white_level_dn),
                     isp.white_balance_stage(white_balance_gains(params)),
                     isp.colour_correction_stage(),
                     isp.response_stage(params.response, params.gamma),
                     isp.quantise_stage(params.bit_depth)]


def apply_chain(linear_rgb: np.ndarray, params: ImagingParams, camera, seed: int) -> ImagingResult:
    """Run the chain on one clean linear render.

    linear_rgb: (H, W, 3) float radiance, W m^-2 sr^-1 (the render's linear RGB).
    camera: :class:`scenegen.geometry.camera.Camera` of size (W, H) (for the cos^4 rays and the centre).
    seed: frame seed (:func:`scenegen.imaging.seeds.frame_seed` of scene seed and view index).
    """
    L = np.asarray(linear_rgb)
    H, W = L.shape[:2]
    if L.shape != (H, W, 3) or (camera.width, camera.height) != (W, H):
        raise ValueError(f"linear_rgb must be (H, W, 3) matching the camera's {camera.height}x"
                         f"{camera.width}, got {L.shape}")
    s = params.sensor
    V = vignetting_map(camera, params.vignetting)  # 1
    e_per_L = electrons_per_radiance(params)  # 2 + 3
    mu_e = np.clip(L.astype(np.float64), 0.0, None) * V[..., None] * e_per_L
    if params.bayer is not None:  # 4
        mu_e = bayer.mosaic(mu_e, params.bayer)
    out = expose_sensor(mu_e, exposure_time_s=params.exposure.exposure_time_s,  # 5
                        gain_db=params.exposure.gain_db, sensor=s, seed=seed)
    stages = isp_stages(params)
    img = isp.develop(out.dn, stages)  # 6-10
    wb = white_balance_gains(params)
    record = {
        "stages": list(STAGES),
        "isp": stages,
        "params": asdict(params),
        "electrons_per_radiance": [float(v) for v in e_per_L],
        "system_gain_dn_per_e": s.system_gain(params.exposure.gain_db),
        "white_balance_used": [float(g) for g in wb],
        "white_level_dn": s.white_level_dn,
        "frame_seed": int(seed),
        "seeds": "temporal: default_rng(SeedSequence([frame_seed, crc32(stage)])) for stages "
                 f"{[seeds.STAGE_SHOT, seeds.STAGE_DARK_CURRENT, seeds.STAGE_READ]}; fixed "
                 "pattern: default_rng(SeedSequence([fixed_pattern_seed, crc32(stage)])) for "
                 f"{[seeds.STAGE_PRNU, seeds.STAGE_DSNU]}",
    }
    return ImagingResult(image=img, vignetting=V.astype(np.float32), electrons=out.electrons,
                         raw_dn=out.dn, record=record)
