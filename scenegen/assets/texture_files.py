"""Texture images read from files: a colour texture (sRGB-encoded 8/16-bit PNG or JPEG, decoded
to linear reflectance, :func:`load_image`) and a data image (normal maps, roughness: no sRGB
decoding, :func:`load_data_image`), both (H, W, 3) float32 in [0, 1] in the conventions of
:mod:`scenegen.assets.textures`; decoded from the bytes without OpenCV's log lines
(:mod:`scenegen.quiet`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from scenegen.geometry.color import linear_from_srgb
from scenegen.quiet import decode_image


def load_image(path) -> np.ndarray:
    """Read a PNG/JPEG (8- or 16-bit, grey, RGB or RGBA) as linear float32 (H, W, 3).

    Integer images are taken as sRGB-encoded and decoded with the sRGB EOTF
    (:func:`scenegen.geometry.color.linear_from_srgb`); alpha is dropped; a grey image is replicated to 3 channels.
    Raises ValueError naming the file when it is missing or cannot be decoded.
    """
    p = Path(path)
    if p.is_dir():
        raise ValueError(f"texture image {str(p)!r}: is a directory, expected a PNG or JPEG file")
    if not p.is_file():
        raise ValueError(f"texture image {str(p)!r}: file not found")
    # decoded from the bytes: no cv2.imread None on non-ASCII paths, no OpenCV log lines
    raw = p.read_bytes()
    if not raw:
        raise ValueError(f"texture image {str(p)!r}: the file is empty")
    try:
        img = decode_image(raw)
    except ValueError as e:  # e.g. a header announcing more pixels than OpenCV allows
        raise ValueError(f"texture image {str(p)!r}: {e}") from None
    if img is None:
        raise ValueError(f"texture image {str(p)!r}: OpenCV could not decode it")
    if img.dtype == np.uint8:
        enc = img.astype(np.float64) / 255.0
    elif img.dtype == np.uint16:
        enc = img.astype(np.float64) / 65535.0
    else:
        raise ValueError(f"texture image {str(p)!r}: unsupported sample type {img.dtype} "
                         "(expected 8- or 16-bit PNG/JPEG)")
    if enc.ndim == 2:
        enc = np.repeat(enc[..., None], 3, axis=-1)
    elif enc.shape[2] == 1:
        enc = np.repeat(enc, 3, axis=-1)
    elif enc.shape[2] == 4:
        enc = enc[..., :3]
    enc = enc[..., ::-1]  # OpenCV's BGR -> RGB
    return np.ascontiguousarray(np.clip(linear_from_srgb(enc), 0.0, 1.0), dtype=np.float32)


def load_data_image(path: Path) -> np.ndarray:
    """An 8- or 16-bit image read as data (no sRGB decoding): (H, W, 3) float32 in [0, 1]."""
    try:
        img = decode_image(Path(path).read_bytes())
    except ValueError as e:
        raise ValueError(f"texture image {str(path)!r}: {e}") from None
    if img is None or img.dtype not in (np.uint8, np.uint16):
        raise ValueError(f"texture image {str(path)!r}: OpenCV could not decode it as 8/16-bit")
    a = img.astype(np.float64) / (255.0 if img.dtype == np.uint8 else 65535.0)
    if a.ndim == 2 or a.shape[2] < 3:  # grey (with or without alpha)
        a = np.repeat((a if a.ndim == 2 else a[..., 0])[..., None], 3, axis=2)
    else:
        a = a[..., :3][..., ::-1]  # OpenCV's BGR -> RGB
    return np.ascontiguousarray(a, dtype=np.float32)
