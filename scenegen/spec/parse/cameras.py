"""``cameras:``: model (from the camera-model registry), size, focal length or field of view,
principal point, skew, distortion, plus the camera's optics and imaging chain."""
from __future__ import annotations

import math
from typing import Mapping

from scenegen.geometry.camera import MODELS, CameraModel
from scenegen.geometry.camera.validity import FoldError
from scenegen.located_yaml import Node, suggest
from scenegen.spec.model.cameras import CameraSpec
from scenegen.spec.model.limits import MAX_IMAGE_PIXELS
from scenegen.spec.model.meta import field_info
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import read_fields, yaml_keys
from scenegen.spec.parse.imaging import parse_imaging
from scenegen.spec.parse.optics import OPTICS_KEYS, parse_optics
from scenegen.spec.parse.read import read_float

#: The written fields' keys (size, the focal lengths, principal point and dist read by hand:
#: they depend on each other and on the model) and the camera's nested sections.
KEYS = yaml_keys(CameraSpec) + ("imaging",) + OPTICS_KEYS


def coefficient_order(cm: CameraModel) -> str:
    """The model's coefficients with the optional tails bracketed, e.g. 'k1, k2, p1, p2[, k3[,
    ...]]' for OpenCV's accepted lengths 4, 5, 8, 12."""
    lengths, names = cm.dist_lengths, cm.coefficients
    text = ", ".join(names[:lengths[0]])
    for a, b in zip(lengths, lengths[1:]):
        text += "[, " + ", ".join(names[a:b])
    return text + "]" * (len(lengths) - 1)


def parse_camera(node: Node, name: str, ctx: ParseContext) -> CameraSpec:
    f = node.as_mapping("a camera (a mapping with model, size and fx, fy or fov_deg)")
    f.check(required=("size",), optional=KEYS)
    C = CameraSpec
    values = read_fields(f, C)  # model, skew, mask_beyond_fold, fov_deg
    model = values["model"]
    cm = MODELS[model]
    size_node = f.get("size")
    size = size_node.as_floats(2, "width, height in pixels")
    smallest, largest = field_info(C, "width").meta.lo, field_info(C, "width").meta.hi
    for item, v in zip(size_node.items(), size):
        if not v.is_integer() or v < smallest:
            raise item.error(f"expected a positive whole number of pixels, got {v:g}")
        if v > largest:
            raise item.error(f"expected at most {largest} pixels (MAX_IMAGE_SIDE_PX, docs/scene_spec.md "
                             f"'Limits'), got {v:.12g}")
    W, H = int(size[0]), int(size[1])
    if W * H > MAX_IMAGE_PIXELS:
        raise size_node.error(f"expected at most {MAX_IMAGE_PIXELS:,} pixels per image (MAX_IMAGE_PIXELS, "
                              f"docs/scene_spec.md 'Limits'), got {W} x {H} = {W * H:,}")
    if "fov_deg" in f:
        for bad in ("fx", "fy"):
            if bad in f:
                raise f.get(bad).error("give either fov_deg or fx and fy, not both")
        # As scenegen.geometry.camera.Camera.from_fov: the FoV of the undistorted pinhole.
        fx = fy = (W / 2) / math.tan(math.radians(values["fov_deg"]) / 2)
    else:
        if "fx" not in f:
            raise f.missing("fx", " (or give fov_deg)")
        fx = read_float(f, C, "fx", default=None)
        fy = read_float(f, C, "fy", default=fx)
    cx = read_float(f, C, "cx", default=(W - 1) / 2)
    cy = read_float(f, C, "cy", default=(H - 1) / 2)
    dist = parse_dist(f.get("dist"), model, cm)
    cam = C(name=name, **values, width=W, height=H, fx=fx, fy=fy, cx=cx,
            cy=cy, dist=dist, where=node.where,
            imaging=parse_imaging(f.get("imaging"), name, ctx) if "imaging" in f else None,
            optics=parse_optics(f, model))
    if not (-0.5 <= cx <= W - 0.5 and -0.5 <= cy <= H - 0.5):
        ctx.warn(node, f"principal point ({cx:g}, {cy:g}) lies outside the image")
    check_camera(cam, f.get("dist") or node)
    return cam


def parse_dist(dn: Node | None, model: str, cm: CameraModel) -> tuple[float, ...]:
    """``dist`` of a camera of model ``cm``: one of its accepted lengths; absent: zeros of the
    shortest."""
    if dn is None:
        return (0.0,) * cm.dist_lengths[0]
    if not cm.coefficients:
        if dn.is_sequence and not dn.items():
            return ()
        with_dist = " or ".join(n for n, other in MODELS.items() if other.coefficients)
        raise dn.error(f"a {model} camera has no distortion; use model: {with_dist}, or "
                       "remove dist")
    return dn.as_floats(cm.dist_lengths, f"{model} coefficients {coefficient_order(cm)}")


def check_camera(cam: CameraSpec, node: Node) -> None:
    """Ask scenegen.geometry.camera whether the camera can exist (e.g. a distortion that folds
    over inside the image); its ValueError becomes a SpecError at ``node``."""
    try:
        cam.to_camera()
    except FoldError as e:
        raise node.error(f"impossible camera: {e}; to render it anyway with the pixels beyond the "
                         "fold radius masked (no ray, invalid in every truth map), set "
                         "`mask_beyond_fold: true` on the camera") from None
    except ValueError as e:
        raise node.error(f"impossible camera: {e}") from None


def camera_ref(node: Node, cameras: Mapping[str, CameraSpec]) -> str:
    """A name under `cameras:`."""
    ref = node.as_str("a camera name")
    if ref not in cameras:
        defined = ", ".join(cameras) or "none"
        raise node.error(f"undefined camera {ref!r}{suggest(ref, cameras)}; "
                         f"defined under cameras: {defined}")
    return ref
