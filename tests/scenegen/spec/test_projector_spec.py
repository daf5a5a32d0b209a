"""The projector sensor kind's spec (scenegen.spec.sensors.projector): the ``projectors:`` section
(intrinsics as a camera's, radiometry, pattern sequence), a light member of a rig, the round
trip, the stated response, and bad input as one-line errors (exit 2 from the CLI)."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen import cli
from scenegen.errors import SpecError
from scenegen.imaging.projector_sequences import SEQUENCES, SequenceOptions, frame_entry
from scenegen.spec import parse_spec, same_spec, spec_sha256, spec_to_dict, to_yaml
from scenegen.spec.sensors import LIGHT, SENSOR_KINDS
from scenegen.spec.views import resolve_views

#: A camera and a projector in a rig (line numbers matter).
PROCAM = """\
name: procam
render: {spp: 4}
objects:
  - {name: b, shape: box}
cameras:
  cam: {size: [32, 24], fx: 30}
projectors:
  proj:
    intrinsics: {model: opencv, size: [20, 10], fx: 25, cx: 12.5, skew: 0.5, dist: [-0.1, 0.01, 0, 0, 0]}
    intensity_w_sr: [1.0, 0.9, 0.8]
    gamma: 2.2
    black_level: 0.05
    falloff: cos4
rigs:
  r:
    type: multi
    members:
      - {camera: cam}
      - {kind: projector, sensor: proj, rig_from_sensor: {translation: [0.1, 0, 0]}}
views:
  - rig: r
    look_at: [{eye: [0, -3, 1], target: [0, 0, 0]}]
"""


def parse(text, tmp_path):
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


def test_a_projector_is_read_with_its_camera_model_radiometry_and_sequence(tmp_path):
    spec = parse(PROCAM, tmp_path)
    assert SENSOR_KINDS["projector"].produces == LIGHT
    p = spec.sensors["projector"]["proj"]
    cam = p.to_camera()
    assert (cam.model, cam.size, cam.fx, cam.fy, cam.cx, cam.cy, cam.skew) == ("opencv", (20, 10), 25, 25, 12.5, 4.5, 0.5)
    assert cam.dist[:2] == (-0.1, 0.01)
    assert (p.intensity_w_sr, p.gamma, p.black_level, p.falloff_exponent) == ((1.0, 0.9, 0.8), 2.2, 0.05, 4)
    # the rig's views are its camera's: the projector lights them
    assert [v.name for v in resolve_views(spec)] == ["r_cam_0000"]
    # white, black, 5 column bits and 4 row bits, each with its inverse
    seq = p.pattern_sequence()
    assert len(seq.frames) == 2 + 2 * (5 + 4) and seq.frames[0].kind == "white" and seq.frames[3].inverse
    assert seq.images.shape == (20, 10, 20)


def test_the_response_is_black_level_plus_the_gamma_curve(tmp_path):
    values = np.array([0.0, 0.25, 0.5, 1.0, 1.5, -1.0])
    spec_p = parse(PROCAM, tmp_path).sensors["projector"]["proj"]
    expected = 0.05 + 0.95 * np.clip(values, 0, 1) ** 2.2
    assert np.allclose(spec_p.relative_output(values), expected, rtol=0, atol=1e-15)


def test_the_sequence_file_entries_name_each_bit_from_the_least_significant():
    seq = SEQUENCES["gray"](20, 10, SequenceOptions(axes="columns", references=False))
    entries = [frame_entry(f) for f in seq.frames]
    assert [e["name"] for e in entries[:3]] == ["u_bit04", "u_bit04_inv", "u_bit03"]
    code = sum((img[0].astype(int) << e["bit"]) for e, img in zip(entries, seq.images) if not e["inverse"])
    cols = np.arange(20)
    assert np.array_equal(code, cols ^ (cols >> 1))  # the reflected binary code of every column
    assert all(e["axis"] == "columns" and e["n_bits"] == 5 for e in entries)


def test_a_phase_sequence_coarser_than_the_projector_is_refused(tmp_path):
    text = PROCAM.replace("falloff: cos4", "falloff: cos4\n    patterns: phase_shift\n    phase_periods_px: [8, 2]")
    with pytest.raises(SpecError, match="scene.yaml:15: .*the coarsest period 8.0 px is shorter than the u axis"):
        parse(text, tmp_path)


def test_the_projector_round_trips_with_its_values(tmp_path):
    spec = parse(PROCAM, tmp_path)
    d = spec_to_dict(spec)["sensors"]["projector"]["proj"]
    assert d["falloff"] == "cos4" and d["intrinsics"]["skew"] == 0.5
    again = parse(to_yaml(spec), tmp_path)
    assert same_spec(again, spec) and spec_sha256(again) == spec_sha256(spec)


@pytest.mark.parametrize("text,line,message", [
    (PROCAM.replace("falloff: cos4", "falloff: cos3"), 13,
     "projectors.proj.falloff: expected one of 'none', 'cos4' (fall-off law), got 'cos3'"),
    (PROCAM.replace("gamma: 2.2", "gamma: 0"), 11, "gamma: expected a value > 0 and <= 10"),
    (PROCAM.replace("black_level: 0.05", "black_level: 1"), 12, "black_level: expected a value >= 0 and < 1"),
    (PROCAM.replace("skew: 0.5,", "skew: 0.5, shutter: {exposure_s: 0.01},"), 9, "a projector's intrinsics take the camera model keys only"),
    (PROCAM.replace("    intrinsics:", "    lens:"), 9, "unknown key 'lens'"),
    (PROCAM.replace("sensor: proj,", "sensor: pro,"), 19, "undefined projector 'pro'"),
    (PROCAM.replace("      - {kind: projector, sensor: proj, rig_from_sensor: {translation: [0.1, 0, 0]}}",
                    "      - {kind: projector, sensor: proj}\n      - {kind: projector, sensor: proj, name: p2}"), 20,
     "holds the projector 'proj' already; its views are lit by one at most"),
])
def test_a_bad_projector_is_a_one_line_error_at_its_line(tmp_path, text, line, message):
    with pytest.raises(SpecError) as e:
        parse(text, tmp_path)
    assert f"scene.yaml:{line}:" in str(e.value) and message in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_the_cli_refuses_a_bad_projector_with_exit_2(tmp_path, capsys):
    path = tmp_path / "procam.yaml"
    path.write_text(PROCAM.replace("falloff: cos4", "falloff: cos3"))
    assert cli.main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "procam.yaml:13:" in err and "Traceback" not in err
