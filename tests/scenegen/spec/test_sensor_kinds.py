"""Sensor kinds in rigs (scenegen.spec.sensors): a kind added as one module plus one registry line
(the test-only clock of clock_sensor.py) is read from its own section and from rig members; the
camera is a kind like it, and every camera member form is the spec it always was."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from scenegen.errors import SpecError
from scenegen.spec import parse_spec, resolve_views, same_spec, spec_sha256, spec_to_dict, to_yaml
from scenegen.spec.parse.scene import TOP_LEVEL_KEYS
from scenegen.spec.sensors import SENSOR_KINDS, STREAM, VIEWS, SensorKind, SensorRun
from scenegen.spec.views import rig_frames

sys.path.insert(0, str(Path(__file__).parent))
from clock_sensor import CLOCK, ClockSpec, write_clock  # noqa: E402

#: A rig of a camera and a clock 4 ms behind the rig's time, on a 3-frame trajectory.
CLOCKED = """\
name: clocked
render: {spp: 4}
sequence: {fps: 10, frames: 3}
objects:
  - {name: b, shape: box}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [32, 24], fx: 30}
clocks:
  clk0: {}
rigs:
  r:
    type: multi
    members:
      - {camera: cam, name: left}
      - {kind: clock, sensor: clk0, name: tick, rig_from_sensor: {translation: [0.1, 0, 0]}, time_offset_s: 0.004}
views:
  - rig: r
    name: seq
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0, -3, 1], target: [0, 0, 0]}
        - {time_s: 0.2, eye: [0.3, -3, 1], target: [0, 0, 0]}
"""
MULTI = """\
cameras:
  cam: {size: [32, 24], fx: 30}
rigs:
  r: {type: multi, members: [%s]}
views:
  - rig: r
    look_at: [{eye: [0, -3, 1], target: [0, 0, 0]}]
"""
MOVED = "{translation: [0.1, 0, 0], rotation_deg: [0, 5, 0]}"


@pytest.fixture
def clock(monkeypatch):
    monkeypatch.setitem(SENSOR_KINDS, CLOCK.name, CLOCK)  # the one registry line
    return CLOCK


def parse(text, tmp_path):
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


def test_a_registered_kind_is_read_from_its_section_and_its_rig_members(clock, tmp_path):
    spec = parse(CLOCKED, tmp_path)
    assert dict(spec.sensors["clock"]) == {"clk0": ClockSpec(name="clk0")}
    left, tick = spec.rigs["r"].members
    assert (left.kind, left.sensor, left.camera, left.time_offset_s) == ("camera", "cam", "cam", 0.0)
    assert (tick.kind, tick.sensor, tick.time_offset_s) == ("clock", "clk0", 0.004)
    assert np.array_equal(tick.rig_from_sensor.t, [0.1, 0.0, 0.0])
    with pytest.raises(AttributeError, match="'tick' is a clock, not a camera"):
        tick.camera
    # only the camera makes views; the clock's frames are the views' frames
    views = resolve_views(spec)
    assert [v.name for v in views] == ["seq_left_0000", "seq_left_0001", "seq_left_0002"]
    ((vs, frames),) = rig_frames(spec)
    assert vs is spec.view_sets[0]
    assert [(f.frame_index, f.time_s) for f in frames] == [(v.frame_index, v.time_s) for v in views]
    for f, v in zip(frames, views):  # the camera sits at identity in the rig: its pose is the rig's
        assert np.allclose(f.world_from_rig.inverse().matrix, v.cam_from_world.matrix, atol=1e-15)
    run = SensorRun(spec=spec, member=tick, sensor=spec.sensors["clock"]["clk0"], frames=frames, stream="s",
                    writer=None)
    assert run.sample_times_s() == tuple(v.time_s + 0.004 for v in views)


def test_the_resolved_spec_keeps_a_camera_member_s_keys_and_round_trips(clock, tmp_path):
    spec = parse(CLOCKED, tmp_path)
    d = spec_to_dict(spec)
    left, tick = d["rigs"]["r"]["members"]
    assert set(left) == {"name", "camera", "rig_from_cam"}  # as datasets have always held it
    assert tick["kind"] == "clock" and tick["sensor"] == "clk0" and tick["time_offset_s"] == 0.004
    assert set(tick) == {"name", "kind", "sensor", "rig_from_sensor", "time_offset_s"}
    assert d["sensors"] == {"clock": {"clk0": {"name": "clk0"}}}
    again = parse(to_yaml(spec), tmp_path)
    assert same_spec(again, spec) and spec_sha256(again) == spec_sha256(spec)


@pytest.mark.parametrize("member", [f"{{sensor: cam, rig_from_sensor: {MOVED}}}",
                                    f"{{kind: camera, camera: cam, rig_from_cam: {MOVED}}}",
                                    f"{{kind: camera, sensor: cam, rig_from_cam: {MOVED}, time_offset_s: 0}}"])
def test_every_camera_member_form_is_the_spec_it_always_was(tmp_path, member):
    legacy = parse(MULTI % f"{{camera: cam, rig_from_cam: {MOVED}}}", tmp_path)
    spec = parse(MULTI % member, tmp_path)
    assert spec_sha256(spec) == spec_sha256(legacy)
    assert spec_to_dict(spec) == spec_to_dict(legacy)
    assert "sensors" not in spec_to_dict(spec)


@pytest.mark.parametrize("text,line,message", [
    (MULTI % "{kind: clock, sensor: cam}", 4, "expected one of 'camera', 'imu', 'projector' (sensor kind), got 'clock'"),
    ("clocks: {clk0: {}}\n" + MULTI % "{camera: cam}", 1, "unknown key 'clocks'"),
    (MULTI % "{camera: cam, time_offset_s: 0.01}", 4,
     "a camera member samples at its rig's time (time_offset_s 0); got 0.01 s"),
    (MULTI % "{camera: cam, sensor: cam}", 4, "give only one of sensor, camera; found sensor and camera"),
    (MULTI % "{camera: cam, rig_from_clock: {translation: [0, 0, 0]}}", 4, "unknown key 'rig_from_clock'"),
    (MULTI % "{sensor: cma}", 4, "undefined camera 'cma' (did you mean 'cam'?); defined under cameras: cam"),
])
def test_a_bad_member_is_a_one_line_error_at_its_line(tmp_path, text, line, message):
    with pytest.raises(SpecError) as e:
        parse(text, tmp_path)
    assert f"scene.yaml:{line}:" in str(e.value) and message in str(e.value) and "\n" not in str(e.value)


TRAJECTORY = CLOCKED[CLOCKED.index("    trajectory:"):]


@pytest.mark.parametrize("changes,line,message", [
    ([("sensor: clk0", "sensor: clk1")], 16, "undefined clock 'clk1' (did you mean 'clk0'?); defined under clocks: clk0"),
    ([("clk0: {}", "clk0: {rate_hz: 5}")], 10, "unknown key 'rate_hz'"),
    ([("sequence: {fps: 10, frames: 3}\n", ""), (TRAJECTORY, "    look_at: [{eye: [0, -3, 1], target: [0, 0, 0]}]\n")],
     17, "rig 'r' holds the clock 'tick', whose stream samples over time: its view set needs times"),
])
def test_a_bad_stream_sensor_is_a_one_line_error(clock, tmp_path, changes, line, message):
    text = CLOCKED
    for change in changes:
        text = text.replace(*change)
    with pytest.raises(SpecError) as e:
        parse(text, tmp_path)
    assert f"scene.yaml:{line}:" in str(e.value) and message in str(e.value) and "\n" not in str(e.value)


def test_two_view_sets_of_one_name_would_write_one_stream_twice(clock, tmp_path):
    text = CLOCKED + CLOCKED[CLOCKED.index("  - rig: r"):]
    with pytest.raises(SpecError, match="stream 'seq_tick' is made by views\\[0\\] too"):
        parse(text, tmp_path)


def test_a_kind_declares_a_writer_exactly_when_it_writes_a_stream():
    common = dict(section="things", model=ClockSpec, parse=None, truth=(), to_yaml=lambda x: {})
    with pytest.raises(ValueError, match="a stream kind has a write function"):
        SensorKind(name="thing", produces=STREAM, **common)
    with pytest.raises(ValueError, match="a stream kind has a write function"):
        SensorKind(name="thing", produces=VIEWS, write=write_clock, **common)
    with pytest.raises(ValueError, match="produces must be one of"):
        SensorKind(name="thing", produces="images", **common)
    assert SENSOR_KINDS["camera"].produces == VIEWS and "depth_z" in SENSOR_KINDS["camera"].truth


def test_every_kind_has_a_section_of_its_own(clock):
    sections = [k.section for k in SENSOR_KINDS.values()]
    assert len(set(sections)) == len(sections)
    assert [k.section for k in SENSOR_KINDS.values() if k.spec_field is None] == ["imus", "projectors", "clocks"]
    assert all(k.section not in TOP_LEVEL_KEYS for k in SENSOR_KINDS.values() if k.spec_field is None)
