"""What the spec needs to read a camera's photometric chain (``cameras.<name>.imaging``):
metadata of :mod:`scenegen.imaging`'s parameter records, whose defaults stay in that package
(docs/image_formation.md). The parser, ``to_yaml`` and the reference table are generated from
it; ``RawOutput``, ``ImagingParams.raw`` and ``SensorParams.black_level_clip`` are described in
:mod:`scenegen.spec.model.cameras`."""
from __future__ import annotations

from scenegen.geometry.color import BIT_DEPTHS
from scenegen.imaging import ExposureParams, ImagingParams, SensorParams, bayer, presets, response
from scenegen.imaging.vignetting import VignettingParams
from scenegen.spec.model.meta import SEED_MAX, describe_foreign, meta

_POS = dict(lo=0.0, lo_open=True)

describe_foreign(
    ImagingParams,
    preset=meta("imaging preset", choices=tuple(presets.PRESETS), doc_default="none (the "
                "defaults below); a preset's values are the defaults of the keys not given"),
    exposure=meta("scenegen.imaging.ExposureParams", part=True),
    vignetting=meta("scenegen.imaging.VignettingParams", part=True),
    sensor=meta("scenegen.imaging.SensorParams", part=True),
    bayer=meta("Bayer pattern", choices=bayer.PATTERNS + ("none",)),
    demosaic=meta("demosaic method", choices=bayer.DEMOSAIC_METHODS),
    white_balance=meta("R, G, B gains", lo=0.0, lo_open=True, doc_default="auto (neutral "
                       "white)"),
    response=meta("camera response", choices=response.RESPONSES),
    gamma=meta("exponent", **_POS),
    bit_depth=meta("bit depth", choices=BIT_DEPTHS, derived="render.bit_depth"),
)
describe_foreign(
    ExposureParams,
    exposure_time_s=meta("seconds", **_POS),
    f_number=meta("f-number", **_POS),
    lens_transmittance=meta("fraction", lo=0.0, lo_open=True, hi=1.0),
    gain_db=meta("dB", lo=-60.0, hi=60.0),
)
describe_foreign(
    VignettingParams,
    natural_cos4=meta("flag"),
    coeffs=meta("a1, a2, a3 of 1 + a1 r^2 + a2 r^4 + a3 r^6"),
    center_px=meta("u, v in pixels", doc_default="none (the principal point)"),
)
describe_foreign(
    SensorParams,
    pixel_pitch_um=meta("micrometres", **_POS),
    quantum_efficiency=meta("R, G, B fractions", lo=0.0, hi=1.0),
    wavelengths_nm=meta("R, G, B nanometres", **_POS),
    system_gain_dn_per_e=meta("DN per electron", **_POS),
    dark_noise_e=meta("electrons", lo=0.0),
    dark_current_e_per_s=meta("electrons per second", lo=0.0),
    saturation_capacity_e=meta("electrons", **_POS),
    prnu_percent=meta("percent", lo=0.0, hi=100.0),
    dsnu_e=meta("electrons", lo=0.0),
    black_level_dn=meta("DN", lo=0),
    adc_bits=meta("bits", lo=1, hi=16),
    temporal_noise=meta("flag"),
    fixed_pattern_seed=meta("seed", label="", lo=0, hi=SEED_MAX,
                            derived="seeded by the camera name"),
)
