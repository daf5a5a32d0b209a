"""A view's files: encode them (pure) and write them atomically with their hashes, for the writer
and for a worker process whose result the writer's owner records
(:meth:`scenegen.dataset.writer.DatasetWriter.record_view`); and the software versions that
determine the output bytes (a dataset's identity)."""
from __future__ import annotations

import platform
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any, Mapping

import cv2
import numpy as np

from scenegen.dataset.codecs.exr import DEFAULT_EXR_COMPRESSION, encode_exr, pack_channels
from scenegen.dataset.codecs.png import encode_png
from scenegen.dataset.files import atomic_write_files, sha256_bytes, stage_files
from scenegen.dataset.layout import CAMERAS, check_rel_path, check_view_name, view_paths
from scenegen.dataset.truth import LINEAR_CHANNELS, encode_truth


def encode_view(view: str, *, image: np.ndarray, linear_rgb: np.ndarray,
                truth: Mapping[str, np.ndarray], exr_compression: str = DEFAULT_EXR_COMPRESSION) -> dict[str, bytes]:
    """Encode one view's files: ``{relative path: bytes}`` (pure; writes nothing).

    image: (H, W, 3) RGB or (H, W) grey, uint8 or uint16 (the rendered, possibly corrupted image).
    linear_rgb: (H, W, 3) float, clean linear radiance (stored as float32).
    truth: see :func:`check_truth`.
    exr_compression: the three EXR files' (:data:`~scenegen.dataset.codecs.exr.EXR_COMPRESSIONS`).
    """
    paths = view_paths(view)
    image = np.asarray(image)
    hw = image.shape[:2]
    linear_rgb = np.asarray(linear_rgb)
    if not np.issubdtype(linear_rgb.dtype, np.floating) or linear_rgb.shape != hw + (3,):
        raise ValueError(f"linear_rgb must be a float {hw + (3,)} array, got {linear_rgb.dtype}"
                         f" {linear_rgb.shape}")
    linear_rgb = linear_rgb.astype(np.float32, copy=False)
    truth_files = encode_truth(truth, shape=hw, exr_compression=exr_compression)
    return {
        paths["image"]: encode_png(image),
        paths["linear"]: encode_exr(pack_channels("", linear_rgb, LINEAR_CHANNELS), exr_compression),
        **{paths[k]: data for k, data in truth_files.items()},
    }


def checked_extra_files(view: str, extra_files: Mapping[str, bytes] | None,
                         standard: Mapping[str, Any]) -> dict[str, bytes]:
    extra = {}
    for rel, data in (extra_files or {}).items():
        check_rel_path(rel)
        if rel in standard or rel == CAMERAS:
            raise ValueError(f"extra file {rel!r} of view {view!r} collides with a standard file")
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise TypeError(f"extra file {rel!r}: pass encoded bytes (see scenegen.dataset.codecs)")
        extra[rel] = bytes(data)
    return extra


def write_view_files(out_dir, view: str, *, image, linear_rgb, truth,
                     extra_files: Mapping[str, bytes] | None = None,
                     exr_compression: str = DEFAULT_EXR_COMPRESSION) -> dict[str, str]:
    """Write one view's files atomically under ``out_dir``; return ``{relative path: sha256}``.

    Does not touch the manifest: for a worker process, whose result the process owning the
    :class:`DatasetWriter` then records with :meth:`DatasetWriter.record_view`.
    ``extra_files`` maps further relative paths to encoded bytes, hashed and listed with the view.
    """
    files = encode_view(view, image=image, linear_rgb=linear_rgb, truth=truth, exr_compression=exr_compression)
    files.update(checked_extra_files(view, extra_files, files))
    root = Path(out_dir)
    hashes = {rel: sha256_bytes(data) for rel, data in files.items()}
    atomic_write_files({root / rel: data for rel, data in files.items()})
    return hashes


@dataclass(frozen=True)
class StagedView:
    """A view's files encoded, hashed and fsync'd under temporary names, not yet renamed:
    :meth:`scenegen.dataset.writer.DatasetWriter.commit_views` renames and records them."""

    view: str
    hashes: dict  # {relative path: sha256}
    staged: tuple  # ((temporary path, final path), ...)


def stage_view(out_dir, view: str, *, image, linear_rgb, truth, extra_files: Mapping[str, bytes] | None = None,
               exr_compression: str = DEFAULT_EXR_COMPRESSION) -> StagedView:
    """Encode, hash and stage (write and fsync under temporary names) one view's files under
    ``out_dir``: the part of a view's writing that needs no writer state, so any thread may run
    it (:mod:`scenegen.dataset.background` runs several at once). Arguments as in
    :func:`write_view_files`."""
    files = encode_view(view, image=image, linear_rgb=linear_rgb, truth=truth, exr_compression=exr_compression)
    files.update(checked_extra_files(view, extra_files, files))
    check_view_name(view)
    hashes = {rel: sha256_bytes(data) for rel, data in files.items()}
    root = Path(out_dir)
    return StagedView(view, hashes, tuple(stage_files({root / rel: data for rel, data in files.items()})))


def software_versions() -> dict[str, str]:
    """Versions of the software that determine the output bytes (without importing Mitsuba)."""
    def dist_version(name: str) -> str:
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return "not installed"

    return {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "opencv": cv2.__version__,
        "mitsuba": dist_version("mitsuba"),
        "drjit": dist_version("drjit"),
        "openexr": dist_version("OpenEXR"),
        "trimesh": dist_version("trimesh"),
        "scenegen": dist_version("scenegen"),
    }
