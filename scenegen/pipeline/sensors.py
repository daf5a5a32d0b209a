"""The dispatch per sensor kind (:data:`scenegen.spec.sensors.SENSOR_KINDS`): members of a kind
that produces views (the camera) are the views rendered by :mod:`.run`; every member of a stream
kind is written here, by its kind's ``write``, once per rig view set, on the driver after the
views (a stream covers all frames of its view set, whatever ``--frames`` selects, as cameras.json
does)."""
from __future__ import annotations

from scenegen.spec.sensors import SENSOR_KINDS, STREAM, SensorRun, stream_name
from scenegen.spec.views import rig_frames


def stream_runs(spec, writer, scene) -> tuple[SensorRun, ...]:
    """One :class:`SensorRun` per stream member of each rig view set, in spec order; its stream is
    named ``<view set>_<member>``."""
    runs = []
    for vs, frames in rig_frames(spec):
        for member in spec.rigs[vs.rig].members:
            kind = SENSOR_KINDS[member.kind]
            if kind.produces == STREAM:
                runs.append(SensorRun(spec=spec, member=member, sensor=kind.sensors_of(spec)[member.sensor],
                                      frames=frames, stream=stream_name(vs, member), writer=writer,
                                      scene=scene))
    return tuple(runs)


def write_streams(spec, writer, scene) -> tuple[str, ...]:
    """Write every stream member's stream through its kind's writer; returns the stream names."""
    runs = stream_runs(spec, writer, scene)
    for run in runs:
        SENSOR_KINDS[run.member.kind].write(run)
    return tuple(run.stream for run in runs)
