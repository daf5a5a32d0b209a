"""Per-view truth written only when a spec asks for it (the optional ``truth:`` section): the
diffuse albedo the renderer used and each image's calibrated lights (photometric stereo), the
circle of confusion of a thin lens (depth from focus and defocus), 2D and 3D bounding boxes per
object; docs/dataset_format.md, "Albedo and light truth", "Defocus truth", "Bounding boxes"."""
from __future__ import annotations

from dataclasses import dataclass

from scenegen.errors import Where
from scenegen.spec.model.meta import param, where_field


@dataclass(frozen=True, kw_only=True)
class TruthSpec:
    albedo: bool = param(False, unit="flag")  # truth/<view>_albedo.exr: the diffuse reflectance
    # of the surface each pixel centre's ray hits (linear RGB, per channel)
    lights: bool = param(False, unit="flag")  # truth/<view>_lights.json: every light on in the
    # view, stated in the camera frame (directions, irradiance, positions)
    defocus: bool = param(False, unit="flag", omit_default=True)  # truth/<view>_coc.exr: the
    # thin-lens circle of confusion of each pixel's truth point (cameras with a `lens:`)
    boxes: bool = param(False, unit="flag", omit_default=True)  # truth/<view>_boxes.json: every
    # object's visible and amodal 2D boxes and its 3D box in the object frame, with its poses
    objects: bool = param(False, unit="flag", omit_default=True)  # truth/<view>_objects.json and
    # _objects.npz: every annotated object's pose, visible fraction, visible and full masks and
    # boxes, keypoints with their visibility (objects with an `annotation:`)
    where: Where | None = where_field()
