"""The raw mosaic and the ISP after it (issue 19), without rendering.

* The delivered image is reproduced to the last DN from the raw mosaic by the recorded ISP
  stages, run by the code docs/image_formation.md prints (OpenCV and numpy only, reading the
  JSON record: the ``develop_from_record`` fixture), for every preset and ISP option.
* DN below the black level stay in the raw mosaic unless the sensor declares black clipping;
  the dark signal is then unbiased (the bias the clipping caused is measured here too).
* The DNG colour data follow the chain's colour model.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from scenegen.dataset.codecs.json import decode_json, encode_json
from scenegen.geometry.camera import Camera
from scenegen.geometry.color import XYZ_FROM_LINEAR_SRGB
from scenegen.imaging import RawOutput, apply_chain
from scenegen.imaging.chain import electrons_per_radiance, neutral_white_balance
from scenegen.imaging.presets import PRESETS
from scenegen.imaging.raw import as_shot_neutral, color_matrix_xyz_to_camera
from scenegen.imaging.stage import raw_view_record

#: Issue 19: the dark-signal mean from the raw files within 0.05 DN of the model.
DARK_MEAN_TOL_DN = 0.05


def _scene(params, camera, seed=0) -> np.ndarray:
    """A linear image with smooth shading, hard edges, colour and saturated / black areas."""
    H, W = camera.height, camera.width
    v, u = np.mgrid[0:H, 0:W].astype(np.float64)
    rng = np.random.default_rng(seed)
    sat = params.sensor.saturation_capacity_e / np.max(electrons_per_radiance(params))
    base = 0.6 * (0.5 + 0.5 * np.sin(u / 7.0) * np.cos(v / 5.0))
    checker = ((u // 8 + v // 8) % 2)[..., None] * np.array([0.8, 0.3, 0.1])
    img = (base[..., None] * np.array([1.0, 0.8, 0.6]) + 0.4 * checker
           + 0.02 * rng.random((H, W, 3)))
    img[:6] = 0.0  # black rows: noise around the black level
    img[-6:] = 2.0  # beyond saturation
    return (img * sat).astype(np.float32)


VARIANTS = {
    "as_shipped": {},
    "grbg_edge_aware_gamma16": dict(bayer="GRBG", demosaic="edge_aware", response="gamma",
                                    gamma=1.8, bit_depth=16),
    "bggr_linear_white_balance": dict(bayer="BGGR", response="linear", white_balance=(1.7, 1.0, 2.1)),
    "gbrg_black_clip": dict(bayer="GBRG", sensor_kw=dict(black_level_clip=True)),
}


def _params(preset, variant):
    kw = dict(VARIANTS[variant])
    p = PRESETS[preset]
    sensor = dataclasses.replace(p.sensor, **kw.pop("sensor_kw", {}))
    return dataclasses.replace(p, sensor=sensor, raw=RawOutput(), **kw)


@pytest.mark.parametrize("variant", sorted(VARIANTS))
@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_delivered_image_is_the_raw_mosaic_through_the_recorded_isp(preset, variant,
                                                                    develop_from_record):
    params = _params(preset, variant)
    camera = Camera.from_fov(60.0, (61, 45))  # odd sizes: the CFA phase at the far borders
    result = apply_chain(_scene(params, camera), params, camera, seed=7)
    record = decode_json(encode_json(raw_view_record(params, "v")))  # as cameras.json holds it
    assert [s["stage"] for s in record["isp"]] == ["demosaic", "normalise", "white_balance",
                                                   "colour_correction", "response", "quantise"]
    assert record["cfa_pattern"] == params.bayer
    assert record["black_level_dn"] == params.sensor.black_level_dn
    assert record["white_level_dn"] == 2 ** params.sensor.adc_bits - 1
    assert record["black_level_clipped"] == params.sensor.black_level_clip
    out = develop_from_record(result.raw_dn, record["isp"])
    assert out.dtype == result.image.dtype and np.array_equal(out, result.image)  # every DN


def _dark(params, seed, size=(256, 256)):
    camera = Camera.from_fov(60.0, size)
    return apply_chain(np.zeros((size[1], size[0], 3), np.float32), params, camera, seed).raw_dn


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_noise_below_black_is_kept_and_the_dark_signal_is_unbiased(preset):
    p = PRESETS[preset]
    s = p.sensor
    K = s.system_gain(p.exposure.gain_db)
    model = s.black_level_dn + K * s.dark_current_e_per_s * p.exposure.exposure_time_s
    dark = _dark(p, seed=3).astype(np.float64)
    below = np.mean(dark < s.black_level_dn)
    print(f"{preset}: {100 * below:.1f} % of dark pixels below black, mean {dark.mean():.4f} vs "
          f"model {model:.4f} DN")
    assert below > 0.05 and dark.min() >= 0
    assert dark.mean() == pytest.approx(model, abs=DARK_MEAN_TOL_DN)
    # clipping at black (what the delivered image's normalisation does) biases the dark signal
    # upwards by about K sigma_d / sqrt(2 pi): 0.34 DN for the machine-vision preset
    clipped = np.maximum(dark, s.black_level_dn)
    print(f"  clipped at black: mean {clipped.mean():.4f} DN, "
          f"{100 * np.mean(clipped == s.black_level_dn):.0f} % exactly at black")
    assert clipped.mean() - model > 0.1 or K * s.dark_noise_e < 1.0


def test_declared_black_clipping_clips_at_black_and_nothing_else():
    p = PRESETS["machine_vision"]
    clip = dataclasses.replace(p, sensor=dataclasses.replace(p.sensor, black_level_clip=True))
    kept, clipped = _dark(p, seed=5), _dark(clip, seed=5)
    assert kept.min() < p.sensor.black_level_dn and clipped.min() == p.sensor.black_level_dn
    assert np.array_equal(clipped, np.maximum(kept, p.sensor.black_level_dn))


def test_the_adc_floor_is_zero_without_clipping():
    p = PRESETS["machine_vision"]
    low = dataclasses.replace(p, sensor=dataclasses.replace(p.sensor, black_level_dn=1))
    dark = _dark(low, seed=1)
    assert dark.min() == 0 and np.mean(dark == 0) > 0.05  # DN below black, down to 0


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_dng_colour_data_follow_the_colour_model(preset):
    p = PRESETS[preset]
    k = electrons_per_radiance(p)
    cm = color_matrix_xyz_to_camera(k)
    # camera RGB of any linear sRGB colour c is proportional to k * c (no crosstalk)
    c = np.random.default_rng(0).random((20, 3))
    cam = (cm @ (XYZ_FROM_LINEAR_SRGB @ c.T)).T
    assert np.allclose(cam, c * k / k.max(), rtol=1e-12, atol=1e-12)
    white = XYZ_FROM_LINEAR_SRGB @ np.ones(3)  # D65, Y = 1
    assert np.max(cm @ white) == pytest.approx(1.0)  # DNG scaling of ColorMatrix1
    # AsShotNeutral of the auto white balance is the camera's response to the D65 white
    neutral = np.array(as_shot_neutral(neutral_white_balance(p)))
    assert np.allclose(neutral, (cm @ white) / (cm @ white)[1], rtol=1e-12)
    assert np.allclose(neutral * np.array(neutral_white_balance(p)), 1.0)  # gains undo it


def test_raw_needs_a_mosaic():
    p = dataclasses.replace(PRESETS["dslr"], bayer=None, raw=RawOutput())
    with pytest.raises(ValueError, match="mosaic"):
        raw_view_record(p, "v")
    assert raw_view_record(PRESETS["dslr"], "v") is None  # no raw asked: no record
