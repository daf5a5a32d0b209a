"""A scenegen dataset's focus stacks: the views of one pose through thin lenses that differ in
their focus distance (cameras.json ``optics.lens``), with the truth depth-from-focus methods are
scored against (z-depth, object ids) and, where written, each view's circle of confusion."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from scenegen.dataset import Dataset
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.color import linear_from_srgb


@dataclass(frozen=True, eq=False)
class FocusStack:
    """K views of one pose, sorted by focus distance (nearest first)."""

    views: tuple[str, ...]
    focus_distance_m: np.ndarray  # (K,) the lens's in-focus depth of each view
    f_number: np.ndarray  # (K,)
    blur_px_per_dioptre: np.ndarray  # (K,) fx A: blur-circle radius (px) per 1/m of defocus
    images_linear: np.ndarray  # (K, H, W) float64: the stored images, sRGB decoded, channel mean
    depth_z: np.ndarray  # (H, W) float64 metres, NaN on misses
    object_id: np.ndarray  # (H, W) uint32
    coc_radius_px: np.ndarray | None  # (K, H, W) float32 truth circle of confusion, None when not written
    objects: dict  # object name -> object id


def _lens(ds: Dataset, view: str) -> dict | None:
    lens = (ds.view_info(view).get("optics") or {}).get("lens")
    if lens is None:
        return None
    try:
        out = {k: float(lens[k]) for k in ("focus_distance_m", "f_number", "pixel_pitch_um")}
    except (KeyError, TypeError, ValueError):
        raise InputError(f"{ds.root}/cameras.json: views.{view}.optics.lens: expected focus_distance_m, f_number, "
                         f"pixel_pitch_um numbers, got {lens!r}") from None
    if not all(np.isfinite(v) and v > 0 for v in out.values()):
        raise InputError(f"{ds.root}/cameras.json: views.{view}.optics.lens: values must be finite and > 0, got {lens!r}")
    return out


def focus_stacks(root, min_views: int = 3) -> list[FocusStack]:
    """Every focus stack (>= ``min_views`` views of one pose with distinct focus distances; 2 for a
    defocus pair) of the dataset at ``root``, in order; NotApplicable when there is none."""
    try:
        ds = Dataset(root)
        groups: dict = {}
        for v in ds.views:
            lens = _lens(ds, v)
            if lens is None:
                continue
            _, pose = ds.camera(v)
            groups.setdefault(tuple(np.round(pose.matrix.ravel(), 12)), []).append((lens["focus_distance_m"], v, lens))
        stacks = [_stack(ds, sorted(g)) for g in groups.values() if len({z for z, _, _ in g}) >= min_views]
    except DatasetError as exc:
        raise InputError(str(exc)) from None
    if not stacks:
        raise NotApplicable(f"{Path(root)}: no focus stack (>= {min_views} views of one pose through lenses focused at "
                            "different distances: cameras.<name>.lens)")
    return stacks


def _grey(img: np.ndarray) -> np.ndarray:
    img = np.asarray(img)
    lin = linear_from_srgb(img / float(np.iinfo(img.dtype).max))
    return lin.mean(axis=-1) if lin.ndim == 3 else lin


def _stack(ds: Dataset, members) -> FocusStack:
    views = tuple(v for _, v, _ in members)
    truth = ds.truth(views[0])
    depth = truth[TruthKind.DEPTH_Z].astype(np.float64)
    depth[~np.isfinite(depth)] = np.nan
    cocs = [ds.coc_radius_px(v) for v in views]
    fx = float(ds.camera(views[0])[0].fx)
    return FocusStack(
        views=views, focus_distance_m=np.array([z for z, _, _ in members]),
        f_number=np.array([lens["f_number"] for _, _, lens in members]),
        blur_px_per_dioptre=np.array([fx * fx * lens["pixel_pitch_um"] * 1e-6 / (2 * lens["f_number"])
                                      for _, _, lens in members]),
        images_linear=np.stack([_grey(ds.image(v)) for v in views]), depth_z=depth,
        object_id=truth[TruthKind.OBJECT_ID],
        coc_radius_px=None if any(c is None for c in cocs) else np.stack(cocs),
        objects={o["name"]: int(o["object_id"]) for o in ds.objects})
