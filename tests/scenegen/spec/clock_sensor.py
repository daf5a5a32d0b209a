"""A test-only sensor kind, added the way docs/architecture.md ("Add a sensor kind") says: this
one module, then one registry line (``SENSOR_KINDS[CLOCK.name] = CLOCK``; the tests use
``monkeypatch.setitem``). A clock in a rig samples at each rig frame's time plus its member's
time offset; its stream holds, per sample, the frame it belongs to and the rig's time, so that a
reader can check ``time_s - rig_time_s == time_offset_s`` exactly."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset import StreamWriter
from scenegen.dataset.streams import StreamField, StreamSchema
from scenegen.errors import Where
from scenegen.spec.model.meta import where_field
from scenegen.spec.sensors import STREAM, SensorKind, SensorRun

FIELDS = (StreamField("frame_index", "int64", unit="frame", doc="the rig frame of the sample"),
          StreamField("rig_time_s", "float64", unit="s", doc="the rig's time at that frame"))


@dataclass(frozen=True, kw_only=True)
class ClockSpec:
    """A clock under ``clocks:``: nothing to set but its name."""

    name: str
    where: Where | None = where_field()


def parse_clock(node, name, ctx) -> ClockSpec:
    node.as_mapping("a clock (an empty mapping)").check()
    return ClockSpec(name=name, where=node.where)


def write_clock(run: SensorRun) -> None:
    """One chunk: every frame's sample time, frame index and rig time."""
    schema = StreamSchema("clock", run.member.sensor, FIELDS)
    sw = StreamWriter(run.writer, run.stream, schema)
    sw.write_chunk(0, np.array(run.sample_times_s()),
                   {"frame_index": np.array([f.frame_index for f in run.frames]),
                    "rig_time_s": np.array([f.time_s for f in run.frames])})
    sw.close()


CLOCK = SensorKind(name="clock", section="clocks", model=ClockSpec, parse=parse_clock, produces=STREAM,
                   truth=tuple(f.name for f in FIELDS), write=write_clock, to_yaml=lambda clock: {})
