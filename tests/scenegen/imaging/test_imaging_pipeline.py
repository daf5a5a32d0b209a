"""The imaging chain inside `scenegen render`: files, records, and the rendered-field check."""
from __future__ import annotations

import json

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset, codecs as sio, verify

#: Issue 4: the image ratio with / without vignetting must reproduce the saved map within 1 %.
RATIO_REL_TOL = 0.01

# A flat white Lambertian wall facing the cameras: an emitting Lambertian panel (a light box, the
# usual flat-field target) of radiance 0.3, so every pixel sees exactly the same radiance and the
# clean render has no Monte Carlo noise (a reflecting wall would carry the path tracer's noise). Camera `vig` vignettes, `flat` does not;
# both have temporal and fixed-pattern noise off so that the ratio is the map itself (noise, and
# the ratio under noise, are tested in test_imaging_noise / test_imaging_vignetting).
SPEC = """
name: flatfield
seed: 3
render: {spp: 4, max_depth: 2, bit_depth: 16}
lights:
  - {type: area, name: wall, size: [40, 40], position: [1.0, 0, 0], look_at: [0, 0, 0], radiance: 0.3}
cameras:
  vig:
    model: opencv
    size: [64, 48]
    fx: 50
    dist: [-0.05, 0.01, 0, 0]
    imaging:
      preset: machine_vision
      vignetting: {natural_cos4: true, coeffs: [-0.3, 0.05, 0.0], center_px: [30.0, 25.0]}
      sensor: {temporal_noise: false, prnu_percent: 0, dsnu_e: 0}
      bayer: none  # demosaicing interpolates across pixels, so it is not a per-pixel map
      response: linear
  flat:
    model: opencv
    size: [64, 48]
    fx: 50
    dist: [-0.05, 0.01, 0, 0]
    imaging:
      preset: machine_vision
      vignetting: {natural_cos4: false, coeffs: [0, 0, 0]}
      sensor: {temporal_noise: false, prnu_percent: 0, dsnu_e: 0}
      bayer: none  # demosaicing interpolates across pixels, so it is not a per-pixel map
      response: linear
  noisy:
    size: [64, 48]
    fx: 50
    imaging: {preset: smartphone}
  clean: {size: [64, 48], fx: 50}
views:
  - {camera: vig, look_at: [{eye: [0, 0, 0], target: [1, 0, 0]}]}
  - {camera: flat, look_at: [{eye: [0, 0, 0], target: [1, 0, 0]}]}
  - {camera: noisy, look_at: [{eye: [0, 0, 0], target: [1, 0, 0]}, {eye: [0, 0, 0], target: [1, 0, 0]}]}
  - {camera: clean, look_at: [{eye: [0, 0, 0], target: [1, 0, 0]}]}
"""


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    spec = tmp_path_factory.mktemp("spec") / "flat.yaml"
    spec.write_text(SPEC)
    out = tmp_path_factory.mktemp("run") / "a"
    assert main(["render", str(spec), "-o", str(out), "-q"]) == 0
    return out


@pytest.mark.render
def test_files_and_records(rendered):
    d = Dataset(rendered)
    assert verify(rendered).ok
    manifest = json.loads((rendered / "manifest.json").read_text())
    for view in ("vig_0000", "flat_0001", "noisy_0002", "noisy_0003"):
        assert f"truth/{view}_vignetting.exr" in manifest["files"]
    assert not (rendered / "truth/clean_0004_vignetting.exr").exists()  # no imaging block
    cams = json.loads((rendered / "cameras.json").read_text())
    assert cams["spec"]["cameras"]["vig"]["imaging"]["preset"] == "machine_vision"
    assert cams["spec"]["cameras"]["clean"]["imaging"] is None
    used = cams["spec"]["imaging_used"]
    assert set(used["cameras"]) == {"vig", "flat", "noisy"}
    assert len(set(used["view_frame_seeds"].values())) == 4
    assert d.image("noisy_0002").dtype == np.uint16  # follows render.bit_depth


@pytest.mark.render
def test_rendered_flat_field_ratio_reproduces_saved_map(rendered):
    vig = Dataset(rendered).image("vig_0000").astype(np.float64)
    flat = Dataset(rendered).image("flat_0001").astype(np.float64)
    V = sio.read_exr(rendered / "truth/vig_0000_vignetting.exr")["V"].astype(np.float64)
    V_flat = sio.read_exr(rendered / "truth/flat_0001_vignetting.exr")["V"]
    assert np.all(V_flat == 1.0) and V.min() < 0.6  # the map has real falloff
    err = np.abs(vig / flat / V[..., None] - 1.0)
    print(f"rendered flat field: vignetting ratio error max {err.max():.2e}")
    assert err.max() < RATIO_REL_TOL


@pytest.mark.render
def test_two_frames_of_one_camera_get_different_noise(rendered):
    d = Dataset(rendered)
    a, b = d.image("noisy_0002"), d.image("noisy_0003")
    assert not np.array_equal(a, b)  # same pose and render, different frame seed
