"""The pipeline writes each rig member through its sensor kind (scenegen.pipeline.sensors): a
test-only clock kind, registered with one line, is parsed from YAML, written as a stream beside
the camera's views, verified, and read back by ``Dataset.streams``; a resumed run keeps the bytes."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from scenegen.dataset import Dataset, verify
from scenegen.pipeline.run import render_spec
from scenegen.spec.sensors import SENSOR_KINDS

sys.path.insert(0, str(Path(__file__).parents[1] / "spec"))
from clock_sensor import CLOCK  # noqa: E402
from test_sensor_kinds import CLOCKED  # noqa: E402

pytestmark = pytest.mark.render


@pytest.fixture
def clocked(monkeypatch, tmp_path):
    monkeypatch.setitem(SENSOR_KINDS, CLOCK.name, CLOCK)  # the one registry line
    spec = tmp_path / "clocked.yaml"
    spec.write_text(CLOCKED)
    out = tmp_path / "out"
    render_spec(spec, out, progress=False)
    return spec, out


def test_a_stream_sensor_is_written_verified_and_read_back(clocked):
    spec, out = clocked
    report = verify(out)
    assert report.ok, report.summary()
    d = Dataset(out)
    assert d.views == ("seq_left_0000", "seq_left_0001", "seq_left_0002")
    assert d.streams.names == ("seq_tick",) and d.streams.of_kind("clock") == ("seq_tick",)
    s = d.streams["seq_tick"]
    assert (s.kind, s.sensor, s.samples) == ("clock", "clk0", 3)
    view_times = np.array([d.cameras["views"][v]["time_s"] for v in d.views])
    assert np.array_equal(s.field("rig_time_s"), view_times)  # the frames the camera rendered
    assert np.array_equal(s.time_s, view_times + 0.004)  # the member's time offset, added once
    assert np.array_equal(s.field("frame_index"), [0, 1, 2])
    assert tuple(f.name for f in s.schema.fields) == CLOCK.truth


def test_a_resumed_run_rewrites_the_stream_to_the_same_bytes(clocked):
    spec, out = clocked
    files = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    render_spec(spec, out, progress=False, resume=True)
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == files
