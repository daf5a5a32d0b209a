"""Photometric image formation: clean linear radiance -> the image a camera would deliver.

A separate, seeded, recorded stage after the clean render (the truth stays exact). Modules, in
chain order (see :mod:`scenegen.imaging.chain` and docs/image_formation.md):

* :mod:`.exposure`   radiance (W m^-2 sr^-1) -> mean photons per pixel (camera equation)
* :mod:`.vignetting` natural cos^4 falloff x polynomial V(r) about a centre (the saved truth map)
* :mod:`.bayer`      colour filter array sampling and OpenCV demosaicing
* :mod:`.noise`      EMVA 1288 sensor: QE, shot / dark / read noise, PRNU, DSNU, full well, ADC
* :mod:`.response`   white balance, camera response (sRGB / gamma / linear), output quantisation
* :mod:`.isp`        the stages after the sensor as a recorded list, and :func:`.isp.develop`
* :mod:`.raw`        raw output options and the DNG colour data (colour matrix, as-shot neutral)
* :mod:`.presets`    named cameras with documented sources
* :mod:`.seeds`      seed derivation (scene seed, view index, stage) and fixed-pattern seeds

numpy only at import; OpenCV is imported where demosaicing needs it. Nothing here imports the
spec layer or Mitsuba.
"""
from scenegen.imaging.chain import ImagingParams, ImagingResult, apply_chain
from scenegen.imaging.exposure import ExposureParams
from scenegen.imaging.noise import SensorParams
from scenegen.imaging.raw import RawOutput
from scenegen.imaging.vignetting import VignettingParams

__all__ = ["ImagingParams", "ImagingResult", "apply_chain", "ExposureParams", "RawOutput",
           "SensorParams", "VignettingParams"]
