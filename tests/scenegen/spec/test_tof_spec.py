"""The ToF camera's spec (scenegen.spec.sensors.tof): the ``tof_cameras:`` section, its camera
reference and frequency rules as one-line errors at their line, its round trip."""
from __future__ import annotations

import pytest

from scenegen import cli
from scenegen.errors import SpecError
from scenegen.spec import parse_spec, same_spec, spec_sha256, spec_to_dict, to_yaml
from scenegen.spec.sensors import SENSOR_KINDS
from scenegen.spec.sensors.tof import TOF, TOF_FIELD_NAMES

#: A ToF camera beside an RGB camera in a rig (line numbers matter).
KINECT = """\
name: kinect
sequence: {fps: 10, frames: 2}
objects:
  - {name: b, shape: box}
cameras:
  rgb: {size: [32, 24], fx: 30}
  ir: {size: [32, 24], fx: 25}
tof_cameras:
  depth0: {camera: ir, frequency_mhz: 100, frequency2_mhz: 80, spp: 4, noise: false}
rigs:
  k:
    type: multi
    members:
      - {camera: rgb, name: rgb}
      - {kind: tof, sensor: depth0, name: depth, rig_from_sensor: {translation: [0.05, 0, 0]}, time_offset_s: 0.002}
views:
  - rig: k
    name: seq
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0, -3, 1], target: [0, 0, 0]}
        - {time_s: 0.1, eye: [0.3, -3, 1], target: [0, 0, 0]}
"""


def parse(text, tmp_path):
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


def test_the_tof_camera_is_a_registered_stream_kind_read_with_its_member(tmp_path):
    assert SENSOR_KINDS["tof"] is TOF and TOF.section == "tof_cameras" and TOF.produces == "stream"
    assert {"raw_dn", "range_m", "range_true_m", "multipath_error_m", "wrap_count", "flying"} <= set(TOF.truth)
    assert TOF.truth == TOF_FIELD_NAMES
    spec = parse(KINECT, tmp_path)
    t = spec.sensors["tof"]["depth0"]
    assert (t.camera, t.freqs_hz, t.spp, t.noise) == ("ir", (100e6, 80e6), 4, False)
    member = spec.rigs["k"].members[1]
    assert (member.kind, member.sensor, member.time_offset_s) == ("tof", "depth0", 0.002)


def test_the_tof_camera_round_trips(tmp_path):
    spec = parse(KINECT, tmp_path)
    assert spec_to_dict(spec)["sensors"]["tof"]["depth0"]["frequency2_mhz"] == 80.0
    again = parse(to_yaml(spec), tmp_path)
    assert same_spec(again, spec) and spec_sha256(again) == spec_sha256(spec)


@pytest.mark.parametrize("old,new,message", [
    ("camera: ir,", "camera: tof,", "no camera 'tof' in cameras: (known: ir, rgb)"),
    ("frequency2_mhz: 80", "frequency2_mhz: 100", "the second frequency must differ from frequency_mhz"),
    ("frequency2_mhz: 80", "frequency2_mhz: 80.0000001", "a frequency pair must be whole hertz"),
    ("frequency_mhz: 100", "frequency_mhz: 0", "frequency_mhz: expected a value > 0"),
    ("spp: 4", "spp: 0", "spp: expected"),
    ("noise: false", "noise: false, gain: 2", "unknown key 'gain'"),
])
def test_a_bad_tof_camera_is_a_one_line_error_at_its_line(tmp_path, old, new, message):
    with pytest.raises(SpecError) as e:
        parse(KINECT.replace(old, new), tmp_path)
    assert "scene.yaml:9:" in str(e.value) and message in str(e.value) and "\n" not in str(e.value)


def test_the_cli_refuses_an_unknown_tof_camera_with_exit_2(tmp_path, capsys):
    path = tmp_path / "kinect.yaml"
    path.write_text(KINECT.replace("camera: ir,", "camera: tof,"))
    assert cli.main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "kinect.yaml:9:" in err and "Traceback" not in err
