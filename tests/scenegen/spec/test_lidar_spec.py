"""The LiDAR sensor kind's spec (scenegen.spec.sensors.lidar): the ``lidars:`` section with its
presets (the public tables they state), explicit values over a preset's, the round trip, and bad
input as one-line errors at the line (exit 2 from the CLI)."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen import cli
from scenegen.errors import SpecError
from scenegen.geometry.lidar_presets import LIDAR_PRESETS
from scenegen.spec import parse_spec, same_spec, spec_sha256, to_yaml
from scenegen.spec.sensors import SENSOR_KINDS
from scenegen.spec.sensors.lidar import LIDAR

#: A LiDAR moving at 10 m/s along +x towards a wall at x = 19.9 .. 20.1, a box crossing its view
#: at 60 m/s; its frame (x forward, y left, z up) from the rig's camera frame by the matrix
#: (line numbers matter).
STREET = """\
name: lidar_test
render: {spp: 1}
sequence: {fps: 10, frames: 2}
objects:
  - name: wall
    shape: {type: box, size: [0.2, 40, 10]}
    transform: {translation: [20, 0, 0]}
  - name: car
    shape: {type: box, size: [2, 2, 2]}
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, translation: [10, 6, 0]}
        - {time_s: 0.2, translation: [10, -6, 0]}
lights: [{type: constant, radiance: 1}]
cameras: {cam: {size: [32, 24], fx: 30}}
lidars:
  l0: {elevations_deg: [-10, -3, 3, 10], firing_offsets_us: [0, 10, 20, 30], columns: 64, rate_hz: 10, object_reflectivity: {car: 0.9}}
rigs:
  r:
    type: multi
    members:
      - {camera: cam, name: cam}
      - {kind: lidar, sensor: l0, name: lidar, rig_from_sensor: {matrix: [[0, -1, 0, 0], [0, 0, -1, 0], [1, 0, 0, 0], [0, 0, 0, 1]]}}
views:
  - rig: r
    name: seq
    trajectory:
      interpolation: linear
      keyframes:
        - {time_s: 0.0, eye: [0, 0, 0], target: [1, 0, 0]}
        - {time_s: 0.2, eye: [2, 0, 0], target: [3, 0, 0]}
"""


def parse(text, tmp_path):
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


def test_the_lidar_is_a_registered_stream_kind():
    assert SENSOR_KINDS["lidar"] is LIDAR and LIDAR.section == "lidars" and LIDAR.produces == "stream"
    assert {"range_m", "point_sensor_m", "point_world_m", "object_id", "instance_id", "incidence_rad",
            "beam_time_s"} <= set(LIDAR.truth)


def test_presets_give_the_public_tables_and_written_keys_override_them(tmp_path):
    text = STREET.replace("l0: {elevations_deg", "os1: {preset: ouster_os1_64}\n  hdl: {preset: velodyne_hdl64e, "
                          "columns: 1024}\n  l0: {elevations_deg")
    spec = parse(text, tmp_path)
    os1, hdl = spec.sensors["lidar"]["os1"], spec.sensors["lidar"]["hdl"]
    assert len(os1.elevations_deg) == 64 and os1.elevations_deg[0] == 16.611 and os1.elevations_deg[-1] == -16.611
    # Ouster's beam_azimuth_angles (3.164, 1.055, -1.055, -3.164) are clockwise: ours are their negatives
    assert os1.azimuth_offsets_deg[:4] == (-3.164, -1.055, 1.055, 3.164) and os1.columns == 2048
    p = os1.scan_pattern()
    assert p.shape == (2048, 64) and np.all(p.beam_time_s[:, 0] == p.beam_time_s[:, 63])  # a column fires at once
    assert hdl.columns == 1024 and hdl.elevations_deg[31] == pytest.approx(2 - 31 / 3, abs=1e-6)
    assert hdl.elevations_deg[32] == -8.83 and hdl.elevations_deg[63] == pytest.approx(-24.33)
    vlp = LIDAR_PRESETS["velodyne_vlp16"]
    assert vlp["elevations_deg"][:4] == (-15.0, 1.0, -13.0, 3.0) and vlp["firing_offsets_us"][15] == pytest.approx(34.56)


def test_the_lidar_round_trips(tmp_path):
    spec = parse(STREET.replace("columns: 64", "preset: velodyne_vlp16, columns: 64"), tmp_path)
    again = parse(to_yaml(spec), tmp_path)
    assert same_spec(again, spec) and spec_sha256(again) == spec_sha256(spec)
    assert again.sensors["lidar"]["l0"].object_reflectivity == {"car": 0.9}


@pytest.mark.parametrize("old,new,line,message", [
    ("elevations_deg: [-10, -3, 3, 10], ", "", 18, "a spinning LiDAR needs elevations_deg (one per channel) or a preset"),
    ("firing_offsets_us: [0, 10, 20, 30]", "firing_offsets_us: [0, 10]", 18,
     "firing_offsets_us: expected 4 values (one per channel of elevations_deg), got 2"),
    ("firing_offsets_us: [0, 10, 20, 30]", "firing_offsets_us: [0, 10, 20, 2000]", 18,
     "every firing offset must be below one column's 1562.5 us (64 columns at 10 Hz), got 2000 us"),
    ("rate_hz: 10", "rate_hz: 5", 26, "sweeps for 0.2 s (5 Hz) from each frame, but frames are 0.1 s apart"),
    ("columns: 64", "columns: 64, preset: hdl", 18, "expected one of 'ouster_os1_64', 'velodyne_hdl64e', "
                                                   "'velodyne_vlp16' (LiDAR preset), got 'hdl'"),
    ("columns: 64", "columns: 64, return_mode: best", 18, "expected one of 'first', 'strongest', 'last'"),
])
def test_a_bad_lidar_is_a_one_line_error_at_its_line(tmp_path, old, new, line, message):
    with pytest.raises(SpecError) as e:
        parse(STREET.replace(old, new), tmp_path)
    assert f"scene.yaml:{line}:" in str(e.value) and message in str(e.value) and "\n" not in str(e.value)


def test_the_cli_refuses_overlapping_sweeps_with_exit_2(tmp_path, capsys):
    path = tmp_path / "lidar.yaml"
    path.write_text(STREET.replace("rate_hz: 10", "rate_hz: 5"))
    assert cli.main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "lidar.yaml:26:" in err and "overlap" in err and "Traceback" not in err
