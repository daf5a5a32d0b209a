"""A scenegen dataset's photometric stereo sets: the views of one camera at one pose, each lit by
one directional light, with the truth a photometric stereo method is scored against (normals,
albedo, depth, object ids) and the calibration it may use (each image's light in the camera
frame, ``truth/<view>_lights.json``). Read through :class:`scenegen.dataset.Dataset`; its errors
become :class:`InputError` naming the file."""
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
class PhotometricSet:
    """One image stack: K images of one camera at one pose, one directional light each."""

    views: tuple[str, ...]  # K views, dataset order
    images_linear: np.ndarray  # (K, H, W, 3) float64: the stored images, sRGB decoded
    directions_cam: np.ndarray  # (K, 3) unit directions toward each image's light, OpenCV camera frame
    # (a point light: from the camera toward it)
    intensities: np.ndarray  # (K, 3) radiance of a white Lambertian surface facing the light, per
    # channel (a point light: at 1 m from it, intensity_w_sr / pi)
    positions_cam: np.ndarray  # (K, 3) point lights' positions (metres, camera frame); NaN rows: directional
    normals_cam: np.ndarray  # (H, W, 3) float64 truth normals, OpenCV camera frame (NaN on misses)
    albedo: np.ndarray | None  # (H, W, 3) float64 truth albedo, or None when not written
    depth_z: np.ndarray  # (H, W) float64 metres, NaN on misses
    object_id: np.ndarray  # (H, W) uint32, 0 = nothing
    fx_px: float  # focal length of the camera (pixels), for integrating normals
    camera: object  # scenegen.geometry.camera.Camera of the views
    objects: dict  # object name -> object id


def _read(fn, *args):
    try:
        return fn(*args)
    except DatasetError as exc:
        raise InputError(str(exc)) from None


def photometric_sets(root, min_views: int = 3) -> list[PhotometricSet]:
    """Every photometric stereo set of the dataset at ``root`` (views grouped by camera and
    pose, in order; a group needs ``min_views`` views with one directional light each; 1 for
    shape from shading). NotApplicable when the dataset has none (no ``truth: {lights: true}``,
    or no such views)."""
    try:
        ds = Dataset(root)
    except DatasetError as exc:
        raise InputError(str(exc)) from None
    groups: dict = {}
    for v in ds.views:
        lights = _read(ds.lights, v)
        if not lights or len(lights) != 1 or lights[0].type not in ("directional", "point"):
            continue
        cam, pose = _read(ds.camera, v)
        key = (ds.view_info(v).get("camera_name"), tuple(np.round(pose.matrix.ravel(), 12)))
        groups.setdefault(key, []).append((v, lights[0]))
    sets = [_stack(ds, members) for members in groups.values() if len(members) >= min_views]
    if not sets:
        raise NotApplicable(f"{Path(root)}: no photometric set (>= {min_views} views of one camera and pose, each "
                            "lit by one directional or point light, with truth/<view>_lights.json: spec truth.lights)")
    return sets


def _stack(ds: Dataset, members) -> PhotometricSet:
    views = tuple(v for v, _ in members)
    first = views[0]
    truth = _read(ds.truth, first)
    albedo = _read(ds.albedo, first)
    images = []
    for v in views:
        img = np.asarray(_read(ds.image, v))
        if img.ndim == 2:
            img = np.repeat(img[..., None], 3, axis=2)
        images.append(linear_from_srgb(img / float(np.iinfo(img.dtype).max)))
    depth = truth[TruthKind.DEPTH_Z].astype(np.float64)
    depth[~np.isfinite(depth)] = np.nan
    cam, _ = _read(ds.camera, first)
    lights = [li for _, li in members]
    pos = np.array([li.position_cam if li.type == "point" else (np.nan,) * 3 for li in lights], np.float64)
    dirs = np.array([li.direction_to_light_cam if li.type == "directional" else p / np.linalg.norm(p)
                     for li, p in zip(lights, pos)], np.float64)
    inten = np.array([li.intensity if li.type == "directional" else np.array(li.intensity_w_sr) / np.pi
                      for li in lights], np.float64)
    return PhotometricSet(
        views=views, images_linear=np.stack(images), directions_cam=dirs, intensities=inten, positions_cam=pos,
        normals_cam=truth[TruthKind.NORMALS_CAM].astype(np.float64),
        albedo=None if albedo is None else albedo.astype(np.float64),
        depth_z=depth, object_id=truth[TruthKind.OBJECT_ID], fx_px=float(cam.fx), camera=cam,
        objects={o["name"]: int(o["object_id"]) for o in ds.objects})
