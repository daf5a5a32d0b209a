"""The per-pixel truth kinds, named once: :class:`TruthKind`, each kind's storage
(:data:`TRUTH_KIND_INFO`) and the key sets derived from it. Only numpy: a sensor kind of the
spec layer names its truth kinds without importing the codecs (:mod:`.truth` re-exports all of
it with the rules, encode and decode).
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np


class TruthKind(str, Enum):
    """The per-pixel truth kinds: the one place their names are written. A member equals its
    string (``TruthKind.DEPTH_Z == "depth_z"``, same hash, formats as the string), so truth dicts,
    EXR channels and JSON keep today's names; :attr:`info` holds each kind's storage."""

    DEPTH_Z = "depth_z"
    RANGE = "range"
    POINTS_WORLD = "points_world"
    POINTS_CAM = "points_cam"
    NORMALS_WORLD = "normals_world"
    NORMALS_CAM = "normals_cam"
    UV = "uv"
    OBJECT_ID = "object_id"
    INSTANCE_ID = "instance_id"
    VALID = "valid"

    __str__ = str.__str__  # the string itself, as enum.StrEnum (3.11) does
    __format__ = str.__format__

    @property
    def info(self) -> "TruthKindInfo":
        return TRUTH_KIND_INFO[self]


@dataclass(frozen=True)
class TruthKindInfo:
    """How a truth kind is stored. ``dtype``: of the stored array; ``components``: the EXR
    channel suffixes of a vector kind, None for an (H, W) kind; ``exr_prefix``: the EXR channel
    (prefix) in its file; ``unit``; ``file``: the view file holding it (a key of
    :func:`scenegen.dataset.layout.view_paths`: ``truth``, ``ids`` or ``valid``); ``miss``: its
    value where the ray hit nothing."""

    dtype: type
    components: tuple[str, ...] | None
    exr_prefix: str | None
    unit: str
    file: str
    miss: float | int | bool


_XYZ = ("X", "Y", "Z")
#: Each kind's storage, in the order of a truth dict (float kinds, ids, valid).
TRUTH_KIND_INFO: dict[TruthKind, TruthKindInfo] = {
    TruthKind.DEPTH_Z: TruthKindInfo(np.float32, None, "depth_z", "metres along the optical axis", "truth", np.inf),
    TruthKind.RANGE: TruthKindInfo(np.float32, None, "range", "metres from the optical centre", "truth", np.inf),
    TruthKind.POINTS_WORLD: TruthKindInfo(np.float32, _XYZ, "P_world", "metres, world frame", "truth", np.nan),
    TruthKind.POINTS_CAM: TruthKindInfo(np.float32, _XYZ, "P_cam", "metres, OpenCV camera frame", "truth", np.nan),
    TruthKind.NORMALS_WORLD: TruthKindInfo(np.float32, _XYZ, "N_world", "unit vector, world frame", "truth", np.nan),
    TruthKind.NORMALS_CAM: TruthKindInfo(np.float32, _XYZ, "N_cam", "unit vector, camera frame", "truth", np.nan),
    TruthKind.UV: TruthKindInfo(np.float32, ("U", "V"), "uv", "texture coordinates (v = 0 at the top row)",
                                "truth", np.nan),
    TruthKind.OBJECT_ID: TruthKindInfo(np.uint32, None, "object_id", "id (spec object k is k + 1)", "ids", 0),
    TruthKind.INSTANCE_ID: TruthKindInfo(np.uint32, None, "instance_id", "id", "ids", 0),
    TruthKind.VALID: TruthKindInfo(np.bool_, None, None, "bool (png 255 = valid)", "valid", False),
}

#: Truth kind -> (EXR channel prefix, component names); components None = a scalar channel.
TRUTH_FLOAT_CHANNELS: dict[TruthKind, tuple[str, tuple[str, ...] | None]] = {
    k: (i.exr_prefix, i.components) for k, i in TRUTH_KIND_INFO.items() if i.file == "truth"}
#: (H, W) uint32 kinds, 0 = no object; stored as the channels of the same names in truth/<view>_ids.exr.
TRUTH_ID_KEYS: tuple[TruthKind, ...] = tuple(k for k, i in TRUTH_KIND_INFO.items() if i.file == "ids")
#: Every key of a truth dict (writer input and reader output).
TRUTH_KEYS: tuple[TruthKind, ...] = tuple(TRUTH_KIND_INFO)
#: Kinds that are +inf (not NaN) on misses.
TRUTH_DISTANCE_KEYS = (TruthKind.DEPTH_Z, TruthKind.RANGE)


class ProjectorTruthKind(str, Enum):
    """The per-pixel truth of a camera view lit by a projector (structured light), stored apart
    from the camera's own truth in ``truth/<view>_projector.npz`` (docs/dataset_format.md,
    "Structured light"): the projector pixel each camera pixel's truth point projects to, whether
    the projector lights it, and the codes a perfect decoder reads there."""

    PROJECTOR_UV = "projector_uv"
    PROJECTOR_LIT = "projector_lit"
    PROJECTOR_COLUMN = "projector_column"
    PROJECTOR_ROW = "projector_row"
    GRAY_COLUMN = "gray_column"
    GRAY_ROW = "gray_row"
    CLEAR_COLUMN = "clear_column"
    CLEAR_ROW = "clear_row"

    __str__ = str.__str__
    __format__ = str.__format__


#: Each projector truth kind's storage (``components``: the last axis's meaning; ``file``: the
#: npz member is the kind's name).
PROJECTOR_TRUTH_INFO: dict[ProjectorTruthKind, TruthKindInfo] = {
    ProjectorTruthKind.PROJECTOR_UV: TruthKindInfo(
        np.float64, ("u", "v"), None, "projector pixels, OpenCV centres, of the stored points_world (float64)",
        "projector", np.nan),
    ProjectorTruthKind.PROJECTOR_LIT: TruthKindInfo(
        np.bool_, None, None, "bool: inside the projector image, facing it, nothing between", "projector", False),
    ProjectorTruthKind.PROJECTOR_COLUMN: TruthKindInfo(
        np.int32, None, None, "projector column index floor(u + 0.5) where lit", "projector", -1),
    ProjectorTruthKind.PROJECTOR_ROW: TruthKindInfo(
        np.int32, None, None, "projector row index floor(v + 0.5) where lit", "projector", -1),
    ProjectorTruthKind.GRAY_COLUMN: TruthKindInfo(
        np.int32, None, None, "Gray code of the column: c ^ (c >> 1), where lit", "projector", -1),
    ProjectorTruthKind.GRAY_ROW: TruthKindInfo(
        np.int32, None, None, "Gray code of the row: r ^ (r >> 1), where lit", "projector", -1),
    ProjectorTruthKind.CLEAR_COLUMN: TruthKindInfo(
        np.bool_, None, None, "bool: lit, and the pixel's four corners see lit points of the same projector column",
        "projector", False),
    ProjectorTruthKind.CLEAR_ROW: TruthKindInfo(
        np.bool_, None, None, "bool: lit, and the pixel's four corners see lit points of the same projector row",
        "projector", False),
}
