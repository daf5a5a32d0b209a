"""The camera as a sensor kind: the ``cameras:`` section, rendered by the pipeline's view path
into one image and its per-pixel truth per rig member and frame (docs/dataset_format.md)."""
from __future__ import annotations

from scenegen.dataset.truth_kinds import TRUTH_KEYS
from scenegen.spec.model.cameras import CameraSpec
from scenegen.spec.parse.cameras import parse_camera
from scenegen.spec.sensors.kind import VIEWS, SensorKind

CAMERA = SensorKind(
    name="camera", section="cameras", model=CameraSpec, parse=parse_camera, produces=VIEWS,
    truth=TRUTH_KEYS, spec_field="cameras", member_keys=("camera", "rig_from_cam"),
    # the views of a rig frame share its time: stereo and sequence truth pair members at one time
    time_offsets=False)
