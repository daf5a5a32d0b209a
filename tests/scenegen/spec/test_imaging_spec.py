"""The `cameras.<name>.imaging` block: presets, overrides, defaults, resolved form and hash."""
from __future__ import annotations

from pathlib import Path

from scenegen.imaging import RawOutput, seeds
from scenegen.imaging.presets import PRESETS
from scenegen.spec import load_spec, parse_spec, spec_sha256, spec_to_dict

ROOT = Path(__file__).resolve().parents[3]
BASE = "render: {bit_depth: 16}\ncameras:\n  cam:\n    size: [64, 48]\n    fx: 50\n"


def test_preset_with_overrides():
    spec = parse_spec(BASE + "    imaging:\n      preset: dslr\n      exposure: {gain_db: 12}\n"
                      "      sensor: {dark_noise_e: 5}\n      bayer: none\n      white_balance: [2, 1, 1.5]\n")
    p = spec.cameras["cam"].imaging
    d = PRESETS["dslr"]
    assert p.preset == "dslr" and p.exposure.gain_db == 12.0
    assert p.exposure.exposure_time_s == d.exposure.exposure_time_s  # kept from the preset
    assert p.sensor.dark_noise_e == 5.0 and p.sensor.saturation_capacity_e == d.sensor.saturation_capacity_e
    assert p.bayer is None and p.white_balance == (2.0, 1.0, 1.5)
    assert p.bit_depth == 16  # render.bit_depth
    assert p.sensor.fixed_pattern_seed == seeds.fixed_pattern_seed_for("cam")


def test_no_block_means_clean_path_and_hash_sees_the_block():
    clean = parse_spec(BASE)
    a = parse_spec(BASE + "    imaging: {preset: smartphone}\n")
    b = parse_spec(BASE + "    imaging: {preset: smartphone, exposure: {exposure_time_s: 0.02}}\n")
    assert clean.cameras["cam"].imaging is None
    d = spec_to_dict(a)["cameras"]["cam"]["imaging"]
    assert d["sensor"]["saturation_capacity_e"] == 6000.0 and d["bayer"] == "RGGB"
    assert len({spec_sha256(clean), spec_sha256(a), spec_sha256(b)}) == 3


def test_degraded_camera_scene_uses_a_preset():
    spec = load_spec(ROOT / "scenes/degraded_camera.yaml")
    p = spec.cameras["phone"].imaging
    assert p.preset == "smartphone" and p.bayer == "RGGB" and p.vignetting.natural_cos4


# -- imaging.raw and sensor.black_level_clip (issue 19) -----------------------------------------
#: The resolved form of an imaging block before issue 19: a spec without raw output or black
#: clipping must keep exactly these keys, so its canonical JSON and hash (and every dataset
#: written from it: cameras.json, manifest.json) stay byte-identical.
IMAGING_KEYS_BEFORE_RAW = {"preset", "exposure", "vignetting", "sensor", "bayer", "demosaic",
                           "white_balance", "response", "gamma", "bit_depth"}
SENSOR_KEYS_BEFORE_RAW = {"pixel_pitch_um", "quantum_efficiency", "wavelengths_nm",
                          "system_gain_dn_per_e", "dark_noise_e", "dark_current_e_per_s",
                          "saturation_capacity_e", "prnu_percent", "dsnu_e", "black_level_dn",
                          "adc_bits", "temporal_noise", "fixed_pattern_seed"}


def _imaging(text):
    return parse_spec(BASE + "    imaging:\n" + text).cameras["cam"].imaging


def test_raw_forms():
    assert _imaging("      preset: dslr\n").raw is None  # opt-in
    assert _imaging("      preset: dslr\n      raw: true\n").raw == RawOutput()
    assert _imaging("      preset: dslr\n      raw: false\n").raw is None
    assert _imaging("      preset: dslr\n      raw: {png: true}\n").raw == RawOutput(dng=True, png=True)
    assert _imaging("      preset: dslr\n      raw: {dng: false, png: true}\n").raw == \
        RawOutput(dng=False, png=True)
    assert _imaging("      bayer: GRBG\n      raw: true\n").raw == RawOutput()


def test_black_level_clip_is_off_unless_declared():
    assert all(not p.sensor.black_level_clip for p in PRESETS.values())  # no bundled sensor clips
    assert not _imaging("      preset: machine_vision\n").sensor.black_level_clip
    assert _imaging("      preset: machine_vision\n      sensor: {black_level_clip: true}\n"
                    ).sensor.black_level_clip


def test_resolved_form_without_raw_is_unchanged_and_with_raw_is_hashed():
    plain = parse_spec(BASE + "    imaging: {preset: smartphone}\n")
    d = spec_to_dict(plain)["cameras"]["cam"]["imaging"]
    assert set(d) == IMAGING_KEYS_BEFORE_RAW and set(d["sensor"]) == SENSOR_KEYS_BEFORE_RAW
    raw = parse_spec(BASE + "    imaging: {preset: smartphone, raw: true}\n")
    clip = parse_spec(BASE + "    imaging: {preset: smartphone, sensor: {black_level_clip: true}}\n")
    assert spec_to_dict(raw)["cameras"]["cam"]["imaging"]["raw"] == {"dng": True, "png": False}
    assert spec_to_dict(clip)["cameras"]["cam"]["imaging"]["sensor"]["black_level_clip"] is True
    assert len({spec_sha256(plain), spec_sha256(raw), spec_sha256(clip)}) == 3


def test_bundled_scenes_resolve_without_the_new_keys():
    for path in sorted((ROOT / "scenes").rglob("*.yaml")):
        for cam in spec_to_dict(load_spec(path))["cameras"].values():
            if cam["imaging"] is not None:
                assert set(cam["imaging"]) == IMAGING_KEYS_BEFORE_RAW, path
                assert set(cam["imaging"]["sensor"]) == SENSOR_KEYS_BEFORE_RAW, path
