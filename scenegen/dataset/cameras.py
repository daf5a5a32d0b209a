"""``cameras.json``: every view's camera, pose, rig membership, optics and lights, plus the
resolved spec. The evaluator's and the exporters' one source of cameras and poses.

Layout::

    {"format": "scenegen-dataset", "format_version": 1, "view_order": [view, ...],
     "views": {view: {"camera": Camera.to_dict(), "cam_from_world": {"R": 3x3, "t": 3},
                      "camera_name", "rig", "rig_member", "frame_index",
                      ["view_set"], ["lights"], ["optics"], ["raw"], ["time_s"]}},
     "spec": the resolved spec dict (scenegen.spec.serialize.spec_to_dict)}
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from scenegen.dataset.layout import check_view_name
from scenegen.dataset.manifest import FORMAT, FORMAT_VERSION
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3


@dataclass(frozen=True)
class ViewCamera:
    """One view's entry in cameras.json.

    ``camera`` is a :class:`scenegen.geometry.camera.Camera` (anything with ``to_dict()``) or its dict;
    ``cam_from_world`` maps world points into the OpenCV camera frame (metres).
    """

    camera: Any
    cam_from_world: Rigid3
    camera_name: str  # the spec's camera this view was taken with
    rig: str | None = None  # rig name, None for a free camera
    rig_member: str | None = None  # member name inside the rig
    frame_index: int = 0  # index of the frame (rig pose) this view belongs to
    optics: Mapping[str, Any] | None = None  # lens, shutter, chromatic aberration, camera motion
    view_set: str | None = None  # prefix name of the spec view set the view belongs to
    lights: Mapping[str, float] | None = None  # every spec light -> factor on its spec power
    # used for this view (0 = off); None (older datasets) = not recorded
    raw: Mapping[str, Any] | None = None  # the raw output's record (scenegen.dataset.raw), None
    # for a view without raw files
    time_s: float | None = None  # seconds on the sequence clock (a sequence frame); None = a
    # static scene

    def to_dict(self) -> dict:
        cam = self.camera.to_dict() if hasattr(self.camera, "to_dict") else dict(self.camera)
        pose = self.cam_from_world
        pose = pose.to_dict() if isinstance(pose, Rigid3) else Rigid3.from_dict(pose).to_dict()
        d = {"camera": cam, "cam_from_world": pose, "camera_name": self.camera_name,
             "rig": self.rig, "rig_member": self.rig_member, "frame_index": int(self.frame_index)}
        if self.view_set is not None:
            d["view_set"] = str(self.view_set)
        if self.lights is not None:
            d["lights"] = {str(k): float(v) for k, v in self.lights.items()}
        if self.optics:
            d["optics"] = dict(self.optics)
        if self.raw is not None:
            d["raw"] = dict(self.raw)
        if self.time_s is not None:
            d["time_s"] = float(self.time_s)
        return d


def cameras_document(views: Mapping[str, Any], spec: Mapping[str, Any] | None) -> dict:
    """The cameras.json document of a run: ``views`` maps each view name (in run order) to a
    :class:`ViewCamera` or its dict."""
    entries = {}
    for name, vc in views.items():
        check_view_name(name)
        entries[name] = vc.to_dict() if isinstance(vc, ViewCamera) else dict(vc)
    return {"format": FORMAT, "format_version": FORMAT_VERSION, "view_order": list(entries),
            "views": entries, "spec": spec}


def camera_of(entry: Mapping) -> tuple[Camera, Rigid3]:
    """``(Camera, cam_from_world)`` of a view's cameras.json entry (KeyError/TypeError/ValueError
    naming a bad field)."""
    return Camera.from_dict(entry["camera"]), Rigid3.from_dict(entry["cam_from_world"])
