"""A scenegen dataset's projector-lit views (docs/dataset_format.md, "Structured light"): the
camera images under each pattern, what each pattern codes, the projector's calibration and pose,
and the per-pixel truth a decoder is scored against. Read through
:class:`scenegen.dataset.Dataset`; its errors become :class:`InputError` naming the file.

Pattern entries of ``patterns/<view>/sequence.json`` are read into :class:`PatternFrame` in the
decoders' terms (:mod:`scenegen.geometry.sl_codes`): axis ``columns`` is ``u``, ``rows`` is ``v``;
the file's ``bit`` counts from the least significant bit, ``PatternFrame.bit`` from the most
significant (frame order of the decoders); a phase-shift entry carries ``period_px``, ``step``
and ``shift_rad``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from scenegen.dataset import Dataset
from scenegen.dataset.codecs.exr import read_exr, unpack_channels
from scenegen.dataset.codecs.json import read_json
from scenegen.dataset.codecs.png import read_png
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.layout import pattern_sequence_path, projector_truth_path
from scenegen.dataset.structured_light import decode_pattern_sequence, decode_projector_truth
from scenegen.dataset.truth import LINEAR_CHANNELS
from scenegen.geometry.camera import Camera
from scenegen.geometry.color import linear_from_srgb
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.sl_codes import bits_for

AXIS_NAMES = {"columns": "u", "rows": "v", "u": "u", "v": "v"}
#: Where the decoders read the images: the stored PNG (what the camera delivers, sRGB decoded to
#: linear) or the clean linear EXR of each pattern.
SOURCES = ("png", "linear")


@dataclass(frozen=True)
class PatternFrame:
    """What one stored pattern codes: ``kind`` white / black / gray / binary / phase / other (the
    file's ``kind`` where it gives one; an entry with an axis and a bit and no kind is Gray)."""

    kind: str
    axis: str = ""  # "u" or "v"
    bit: int = -1  # gray: 0 = most significant of n_bits
    n_bits: int = 0
    inverse: bool = False
    period_px: float = 0.0  # phase
    step: int = -1
    shift_rad: float = 0.0


@dataclass(frozen=True, eq=False)
class ProjectorView:
    """One camera view under a projector's pattern sequence, with its truth."""

    view: str
    camera: Camera
    cam_from_world: Rigid3
    projector: Camera
    projector_from_world: Rigid3
    frames: tuple[PatternFrame, ...]
    images: np.ndarray  # (N, H, W) float64 linear grey (mean of RGB), frame order
    truth_uv: np.ndarray  # (H, W, 2) float64 continuous projector pixel of each camera pixel (NaN: none)
    truth_code: np.ndarray  # (H, W, 2) int64 projector column, row a perfect decoder reads (-1: not lit)
    lit: np.ndarray  # (H, W) bool: the projector lights the camera pixel's point
    clear: np.ndarray  # (H, W, 2) bool: lit, the pixel's footprint in one projector column (row)
    depth_z: np.ndarray  # (H, W) float64 metres, NaN on misses
    points_world: np.ndarray  # (H, W, 3) float64 metres, NaN on misses
    frame_index: int  # the view's frame of a sequence (0 without one)


def _frame(entry: dict, projector: Camera, source: str) -> PatternFrame:
    try:
        name, axis = str(entry.get("name", "")), AXIS_NAMES.get(str(entry.get("axis") or ""), "")
        if name in ("white", "black"):
            return PatternFrame(name)
        if "period_px" in entry:
            return PatternFrame("phase", axis, period_px=float(entry["period_px"]), step=int(entry["step"]),
                                shift_rad=float(entry["shift_rad"]))
        if axis and int(entry.get("bit", -1)) >= 0:
            kind = "binary" if entry.get("kind") == "binary" else "gray"
            n = int(entry.get("n_bits") or bits_for(projector.width if axis == "u" else projector.height))
            return PatternFrame(kind, axis, n - 1 - int(entry["bit"]), n, bool(entry.get("inverse", False)))
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"{source}: pattern {entry.get('index')}: unreadable entry ({e})") from None
    return PatternFrame("other", axis)


def _grey(image: np.ndarray) -> np.ndarray:
    scale = 65535.0 if image.dtype == np.uint16 else 255.0
    lin = linear_from_srgb(image.astype(np.float64) / scale)
    return lin.mean(axis=2) if lin.ndim == 3 else lin


def _read_view(ds: Dataset, view: str, source: str) -> ProjectorView:
    seq_path = pattern_sequence_path(view)
    doc = ds.read(seq_path, lambda p: decode_pattern_sequence(read_json(p), str(p)), "pattern sequence")
    where = str(ds.path(seq_path))
    try:
        proj = doc["projector"]
        projector = Camera.from_dict(proj["camera"])
        projector_from_world = Rigid3.from_matrix(proj["projector_from_world"])
    except (KeyError, TypeError, ValueError) as e:
        raise InputError(f"{where}: projector: unreadable ({e})") from None
    frames, images = [], []
    for entry in doc["patterns"]:
        if not isinstance(entry, dict) or not isinstance(entry.get("image"), str):
            raise InputError(f"{where}: a pattern entry without an 'image' path")
        frames.append(_frame(entry, projector, where))
        if source == "linear":
            if not isinstance(entry.get("linear"), str):
                raise InputError(f"{where}: pattern {entry.get('index')}: no linear render ('linear'); "
                                 f"read the images instead")
            lin = ds.read(entry["linear"], lambda p: unpack_channels(read_exr(p), "", LINEAR_CHANNELS), "pattern")
            images.append(np.asarray(lin, np.float64).mean(axis=2))
        else:
            images.append(_grey(ds.read(entry["image"], read_png, "pattern image")))
    t = ds.read(projector_truth_path(view), lambda p: decode_projector_truth(p.read_bytes()), "projector truth")
    camera, cam_from_world = ds.camera(view)
    for entry, img in zip(doc["patterns"], images):
        if img.shape != (camera.height, camera.width) or t.lit.shape != img.shape:
            raise InputError(f"{ds.path(entry['image'])}: a {img.shape} image (projector truth {t.lit.shape}); "
                             f"the view's camera is {camera.height} x {camera.width}")
    depth = ds.depth_z(view).astype(np.float64)
    return ProjectorView(view, camera, cam_from_world, projector, projector_from_world, tuple(frames),
                         np.stack(images), t.uv, np.stack([t.column, t.row], axis=2).astype(np.int64), t.lit,
                         np.stack([t.clear_column, t.clear_row], axis=2),
                         np.where(np.isfinite(depth), depth, np.nan), ds.points_world(view).astype(np.float64),
                         int(ds.view_info(view).get("frame_index") or 0))


def projector_views(root, *, source: str = "png") -> list[ProjectorView]:
    """Every projector-lit view of the dataset at ``root``, in view order; NotApplicable when
    there is none."""
    if source not in SOURCES:
        raise InputError(f"image source must be one of {SOURCES}, got {source!r}")
    try:
        ds = Dataset(root)
        lit = [v for v in ds.views if ds.has(pattern_sequence_path(v))]
        if not lit:
            raise NotApplicable(f"{root}: no projector-lit view (patterns/<view>/sequence.json)")
        return [_read_view(ds, v, source) for v in lit]
    except DatasetError as e:
        raise InputError(str(e)) from None
