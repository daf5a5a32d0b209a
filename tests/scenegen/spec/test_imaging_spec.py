"""The `cameras.<name>.imaging` block: presets, overrides, defaults, resolved form and hash."""
from __future__ import annotations

from pathlib import Path

from scenegen.imaging import seeds
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
