"""Directional lights, the `truth:` section and the lights document (scenegen.spec.light_truth)."""
import numpy as np
import pytest

from scenegen.errors import SpecError
from scenegen.spec import parse_spec, resolve_views, spec_to_dict
from scenegen.spec.light_truth import view_lights_document

CAM = "cameras:\n  cam: {size: [8, 6], fx: 8}\n"
VIEW = "views:\n  - {camera: cam, lights: {sun: 0.5, bulb: 2}, look_at: [{eye: [1, -3, 2], target: [0, 0, 0]}]}\n"
LIGHTS = ("lights:\n  - {type: directional, name: sun, direction_to_light: [0, 0, 2], irradiance: [2, 3, 4]}\n"
          "  - {type: point, name: bulb, position: [0.5, 0.2, 1], intensity: 1}\n"
          "  - {type: constant, name: sky, radiance: 0.1}\n")


def test_lights_document_in_the_camera_frame():
    spec = parse_spec(CAM + LIGHTS + VIEW + "truth: {lights: true}\n")
    (view,) = resolve_views(spec)
    doc = view_lights_document(spec, view)
    sun, bulb = doc["lights"]  # sky is off in the view: not listed
    R, t = view.cam_from_world.R, view.cam_from_world.t
    np.testing.assert_allclose(sun["direction_to_light_cam"], R @ [0, 0, 1], atol=1e-15)
    assert sun["irradiance_w_m2"] == [1.0, 1.5, 2.0] and sun["factor"] == 0.5
    np.testing.assert_allclose(sun["intensity"], np.array([1.0, 1.5, 2.0]) / np.pi, rtol=1e-15)
    np.testing.assert_allclose(bulb["position_cam"], R @ [0.5, 0.2, 1] + t, atol=1e-15)
    assert bulb["intensity_w_sr"] == [2.0, 2.0, 2.0]
    assert spec_to_dict(spec)["truth"] == {"albedo": False, "lights": True}


def test_a_spec_without_truth_keeps_its_resolved_form():
    assert "truth" not in spec_to_dict(parse_spec(CAM + LIGHTS + VIEW))


@pytest.mark.parametrize("text, fragment", [
    (CAM + "lights:\n  - {type: directional, direction_to_light: [0, 0, 0], irradiance: 1}\n", "non-zero direction"),
    (CAM + "lights:\n  - {type: directional, irradiance: 1}\n", "direction_to_light"),
    (CAM + "truth: {normals: true}\n", "normals"),
    (CAM + "truth: {albedo: 1}\n", "albedo"),
])
def test_bad_values_name_their_field(text, fragment):
    with pytest.raises(SpecError) as e:
        parse_spec(text)
    assert fragment in str(e.value)


def test_defocus_truth_without_a_lens_is_a_warning():
    spec = parse_spec(CAM + "truth: {defocus: true}\n")
    assert spec.truth.defocus and any("thin lens" in w for w in spec.warnings)
    assert spec_to_dict(parse_spec(CAM + "truth: {lights: true}\n"))["truth"] == {"albedo": False, "lights": True}


def test_albedo_truth_refuses_motion_at_its_field():
    text = (CAM + "objects:\n  - {name: b, shape: sphere, motion: {linear_velocity_mps: [1, 0, 0]}}\n"
            "truth: {albedo: true}\n")
    with pytest.raises(SpecError) as e:
        parse_spec(text)
    assert "albedo" in str(e.value) and "'b' moves" in str(e.value)
