"""Albedo and light truth as stored (scenegen.dataset.photometric): round trips and refusals."""
import numpy as np
import pytest

from scenegen.dataset.codecs import decode_exr
from scenegen.dataset.photometric import LIGHTS_FORMAT, decode_albedo, decode_lights, encode_albedo


def test_albedo_round_trip_keeps_nan():
    a = np.random.default_rng(0).uniform(size=(4, 5, 3)).astype(np.float32)
    a[0, 0] = np.nan
    b = decode_albedo(decode_exr(encode_albedo(a)))
    np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="albedo"):
        encode_albedo(np.zeros((4, 5)))


def test_lights_document_is_checked_field_by_field():
    good = {"format": LIGHTS_FORMAT, "lights": [{"name": "sun", "type": "directional", "factor": 1.0,
                                                  "direction_to_light_cam": [0, 0, -1], "intensity": [1, 1, 1]}]}
    (light,) = decode_lights(good, "x.json")
    assert light.direction_to_light_cam == (0.0, 0.0, -1.0) and light.position_cam is None
    for bad, fragment in (({"format": "other"}, "scenegen.lights/1"),
                          ({**good, "lights": [{"name": "sun"}]}, "lights[0]"),
                          ({**good, "lights": [{**good["lights"][0], "intensity": [1, 1]}]}, "lights[0].intensity"),
                          ({**good, "lights": [{**good["lights"][0], "factor": -1}]}, "lights[0].factor")):
        with pytest.raises(ValueError, match=fragment.replace("[", r"\[").replace("]", r"\]")) as e:
            decode_lights(bad, "x.json")
        assert "x.json" in str(e.value)
