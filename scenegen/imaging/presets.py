"""Named cameras: starting points for ``imaging: {preset: NAME}``; explicit keys override them.

The output bit depth is not part of a preset (it follows ``render.bit_depth`` in a spec).

Every number is either *measured* (with its source) or *assumed* (a typical value, marked so).
Derived values say how they were derived. Representative wavelengths are assumed for every
preset: R 610 nm, G 540 nm, B 465 nm (peaks of typical RGB colour-filter transmissions).

* ``machine_vision``: Sony IMX174 (Pregius global shutter, 5.86 um pixels), colour version,
  at 0 dB. Measured (EMVA 1288, Point Grey white paper "Sony Pregius Global Shutter CMOS Imaging
  Performance", 2015): QE 77 % at 525 nm (used for G), temporal dark noise 6.83 e-, saturation
  capacity 32,691 e-. Derived: K = (4095 - 64) / 32,691 = 0.1233 DN/e- (the 12-bit ADC spans
  the full well above a 64 DN black level). Assumed: R and B QE 0.60 (colour filters), dark
  current 5 e-/s, PRNU 0.5 %, DSNU 2 e-, black level 64 DN, f/2.8 lens with T = 0.9, 10 ms,
  RGGB, mild natural vignetting only.
* ``smartphone``: a 12 MP, 1.4 um BSI phone sensor of the Sony IMX363 class behind an f/1.8
  lens. Measured/specified: 1.4 um pitch, f/1.8 (manufacturer specifications of the Pixel 3 main
  camera). Assumed: full well 6,000 e-, read noise 2.0 e- (Clark, "Digital Camera Sensor
  Performance Summary", clarkvision.com: modern sensors' read noise is near or under 2 e-),
  QE (0.50, 0.60, 0.50), dark current 50 e-/s, PRNU 1 %, DSNU 1 e-, 10-bit ADC with a 64 DN
  black level (as phone RAW/DNG files commonly have), strong lens shading (cos^4 and
  a1 = -0.35, a2 = 0.05), 1/120 s. Derived: K = (1023 - 64) / 6,000 = 0.160 DN/e-.
* ``dslr``: Canon EOS 5D Mark III at ISO 100. Measured: saturation 67,684 e- at ISO 100 (Magic
  Lantern forum, "dual ISO" thread, raw measurements of the 5D3); 14-bit raw with black level
  2048 DN (Canon's raw offset). Specified: 5760 px over 36 mm, so 6.25 um pitch. Approximate:
  read noise 30 e- at ISO 100 (Canon of that generation is limited by downstream read noise at
  base ISO, cf. Clark's 5D Mark III review on clarkvision.com; ~6 DN at K = 0.21). Derived:
  K = (16383 - 2048) / 67,684 = 0.2118 DN/e-. Assumed: QE (0.45, 0.50, 0.40), dark current
  10 e-/s, PRNU 0.5 %, DSNU 3 e-, f/4 lens with T = 0.9, 1/125 s, natural cos^4 and
  a1 = -0.15.
"""
from __future__ import annotations

from scenegen.imaging.chain import ImagingParams
from scenegen.imaging.exposure import ExposureParams
from scenegen.imaging.noise import SensorParams
from scenegen.imaging.vignetting import VignettingParams

_WAVELENGTHS_NM = (610.0, 540.0, 465.0)

PRESETS: dict[str, ImagingParams] = {
    "machine_vision": ImagingParams(
        preset="machine_vision",
        exposure=ExposureParams(exposure_time_s=0.01, f_number=2.8, lens_transmittance=0.9),
        vignetting=VignettingParams(natural_cos4=True),
        sensor=SensorParams(pixel_pitch_um=5.86, quantum_efficiency=(0.60, 0.77, 0.60),
                            wavelengths_nm=_WAVELENGTHS_NM, system_gain_dn_per_e=0.1233,
                            dark_noise_e=6.83, dark_current_e_per_s=5.0,
                            saturation_capacity_e=32_691.0, prnu_percent=0.5, dsnu_e=2.0,
                            black_level_dn=64, adc_bits=12),
        bayer="RGGB", demosaic="bilinear", response="srgb"),
    "smartphone": ImagingParams(
        preset="smartphone",
        exposure=ExposureParams(exposure_time_s=1 / 120, f_number=1.8, lens_transmittance=0.9),
        vignetting=VignettingParams(natural_cos4=True, coeffs=(-0.35, 0.05, 0.0)),
        sensor=SensorParams(pixel_pitch_um=1.4, quantum_efficiency=(0.50, 0.60, 0.50),
                            wavelengths_nm=_WAVELENGTHS_NM, system_gain_dn_per_e=0.160,
                            dark_noise_e=2.0, dark_current_e_per_s=50.0,
                            saturation_capacity_e=6_000.0, prnu_percent=1.0, dsnu_e=1.0,
                            black_level_dn=64, adc_bits=10),
        bayer="RGGB", demosaic="edge_aware", response="srgb"),
    "dslr": ImagingParams(
        preset="dslr",
        exposure=ExposureParams(exposure_time_s=1 / 125, f_number=4.0, lens_transmittance=0.9),
        vignetting=VignettingParams(natural_cos4=True, coeffs=(-0.15, 0.0, 0.0)),
        sensor=SensorParams(pixel_pitch_um=6.25, quantum_efficiency=(0.45, 0.50, 0.40),
                            wavelengths_nm=_WAVELENGTHS_NM, system_gain_dn_per_e=0.2118,
                            dark_noise_e=30.0, dark_current_e_per_s=10.0,
                            saturation_capacity_e=67_684.0, prnu_percent=0.5, dsnu_e=3.0,
                            black_level_dn=2048, adc_bits=14),
        bayer="RGGB", demosaic="edge_aware", response="srgb"),
}


def preset(name: str) -> ImagingParams:
    """The named preset (KeyError naming the known ones otherwise)."""
    try:
        return PRESETS[name]
    except KeyError:
        raise KeyError(f"unknown imaging preset {name!r}; known: {', '.join(PRESETS)}") from None
