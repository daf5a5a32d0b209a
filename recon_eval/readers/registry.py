"""Which reader reads a path: the formats recon_eval accepts for maps, images and camera poses,
sniffed from the path (suffix, folder contents, numbers per line) in one place.

* Maps (depth, disparity; :func:`read_map`): by suffix, :data:`MAP_READERS`.
* Images (:func:`read_image`): PNG/JPEG, RGB or grey, uint8/uint16.
* Poses (:func:`read_poses`): the first of :data:`POSE_FORMATS` whose sniffer accepts the path: a
  scenegen dataset, a COLMAP model folder (binary, then text), a NeRF ``transforms.json``, a TUM
  trajectory (8 numbers per line) or a KITTI odometry one (12).

Every reader returns recon_eval's conventions (docs/metrics.md, "Inputs") and raises
:class:`recon_eval.errors.InputError` naming the file and what was expected.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.colmap_binary import read_colmap_binary
from recon_eval.readers.colmap_text import read_colmap_text
from recon_eval.readers.exr import read_exr_map
from recon_eval.readers.euroc import is_euroc_groundtruth, read_euroc_groundtruth
from recon_eval.readers.kitti_odometry import read_kitti_poses
from recon_eval.readers.kitti_png import read_kitti_disparity
from recon_eval.readers.nerf import read_nerf_transforms
from recon_eval.readers.npy import read_npy
from recon_eval.readers.pfm import read_pfm
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from recon_eval.readers.text import read_text
from recon_eval.readers.tum import read_tum
from scenegen.dataset import CAMERAS
from recon_eval.readers.native import read_png

# --- maps --------------------------------------------------------------------------------------
#: suffix -> reader(path, kind) of an (H, W) float64 map, NaN = missing ("depth" or "disparity"
#: picks an EXR's channel).
MAP_READERS: dict[str, Callable[[str, str], np.ndarray]] = {
    ".png": lambda path, kind: read_kitti_disparity(path),
    ".pfm": lambda path, kind: read_pfm(path),
    ".npy": lambda path, kind: read_npy(path, (None, None)),
    ".exr": lambda path, kind: read_exr_map(path, kind=kind),
}
MAP_SUFFIXES = tuple(MAP_READERS)
#: Suffixes of a per-view depth estimate ``<view><suffix>`` in a folder, in lookup order.
DEPTH_SUFFIXES = (".npy", ".pfm", ".exr")


def read_map(path, kind: str = "depth") -> np.ndarray:
    """An (H, W) float64 depth or disparity map from a .png (KITTI uint16), .pfm, .npy or .exr."""
    p = Path(path)
    reader = MAP_READERS.get(p.suffix.lower())
    if reader is not None:
        return reader(str(p), kind)
    if p.is_dir():
        raise InputError(f"{p}: is a folder, expected an image file (.png, .pfm, .npy or .exr)")
    raise InputError(f"{p}: unknown image format {p.suffix.lower()!r} (expected .png, .pfm, .npy or .exr)")


def find_view_map(folder, view: str, suffixes=DEPTH_SUFFIXES) -> Path | None:
    """``folder/<view><suffix>`` for the first suffix that exists, else None."""
    return next((Path(folder) / (view + s) for s in suffixes if (Path(folder) / (view + s)).is_file()), None)


# --- images ------------------------------------------------------------------------------------
def read_image(path) -> np.ndarray:
    """An image file (PNG/JPEG) as (H, W, 3) RGB or (H, W) grey, uint8/uint16."""
    p = Path(path)
    try:
        img = read_png(p) if p.is_file() else None
    except ValueError:  # not an image cv2 can decode
        img = None
    if img is None:
        raise InputError(f"{path}: cannot read as an image (expected PNG/JPEG)")
    return img


# --- poses -------------------------------------------------------------------------------------
def sniff_trajectory(path: Path) -> str:
    """'tum' (8 numbers per line, or ov_eval's 20 with covariances) or 'kitti' (12), from the first
    non-comment line."""
    for ln in read_text(path, "a TUM or KITTI trajectory").splitlines():
        ln = ln.split("#", 1)[0].replace(",", " ").strip()
        if ln:
            n = len(ln.split())
            if n in (8, 12, 20):
                return "kitti" if n == 12 else "tum"
            raise InputError(f"{path}:1: expected 8 (TUM) or 12 (KITTI odometry) numbers per line, got {n} "
                             "(20: TUM with ov_eval's covariances)")
    raise InputError(f"{path}: empty trajectory (expected TUM or KITTI lines)")


def subset(poses: Poses, names) -> Poses:
    """The poses named ``names``, in that order."""
    idx = [poses.names.index(n) for n in names]
    return Poses(tuple(names), poses.R_cam_from_world[idx], poses.t_cam_from_world[idx])


def _dataset_poses(path: Path, camera: str | None, kitti_convention: str) -> Poses:
    ds = read_dataset(path)
    poses = ds.poses
    if camera:
        keep = ds.views_of_camera(camera)
        if not keep:
            raise InputError(f"{path / CAMERAS}: camera_name: no complete view of camera {camera!r}")
        poses = subset(poses, keep)
    return poses


@dataclass(frozen=True)
class PoseFormat:
    """A pose source: ``kind`` (recorded in reports), ``sniff(path) -> bool`` and
    ``read(path, camera, kitti_convention)`` -> Poses (TUM: a TumTrajectory, matched by time)."""

    kind: str
    sniff: Callable[[Path], bool]
    read: Callable[[Path, str | None, str], object]


#: In sniffing order; the first format whose ``sniff`` accepts a path reads it.
POSE_FORMATS = (
    PoseFormat("dataset", is_dataset, _dataset_poses),
    PoseFormat("colmap", lambda p: p.is_dir() and (p / "images.bin").is_file(),
               lambda p, camera, conv: read_colmap_binary(p).poses),
    PoseFormat("colmap", lambda p: p.is_dir() and (p / "images.txt").is_file(),
               lambda p, camera, conv: read_colmap_text(p).poses),
    PoseFormat("nerf", lambda p: p.is_file() and p.suffix.lower() == ".json",
               lambda p, camera, conv: read_nerf_transforms(p).poses),
    PoseFormat("tum", is_euroc_groundtruth, lambda p, camera, conv: read_euroc_groundtruth(p)),  # stamped, as TUM
    PoseFormat("tum", lambda p: p.is_file() and sniff_trajectory(p) == "tum", lambda p, camera, conv: read_tum(p)),
    PoseFormat("kitti", lambda p: p.is_file() and sniff_trajectory(p) == "kitti",
               lambda p, camera, conv: read_kitti_poses(p, conv)),
)


def read_poses(path, *, camera: str | None = None, kitti_convention: str = "world_from_cam"):
    """``(kind, poses)`` of any supported pose source (:data:`POSE_FORMATS`). ``camera``: of a
    dataset, only the views of that spec camera; ``kitti_convention``: what a KITTI line holds."""
    p = Path(path)
    for fmt in POSE_FORMATS:
        if fmt.sniff(p):
            return fmt.kind, fmt.read(p, camera, kitti_convention)
    if p.is_dir():
        raise InputError(f"{p}: folder is neither a dataset (manifest.json, cameras.json) nor a COLMAP model "
                         "(images.bin or images.txt)")
    raise InputError(f"{p}: no such file or folder (expected poses: dataset, COLMAP model, transforms.json, "
                     "TUM or KITTI trajectory)")
