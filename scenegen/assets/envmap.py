"""An environment map file read as the renderer will read it, before the renderer does: its size
from the header alone (checked against MAX_TEXTURE_PIXELS before any pixel is allocated), then
the whole image decoded, so ``validate`` refuses what ``render`` would (Mitsuba's own failure is
a bare ``RuntimeError``, and ``std::bad_alloc`` for a header announcing 10^10 pixels).

Formats: what Mitsuba's ``Bitmap`` reads among the spec's image suffixes (EXR, Radiance HDR,
PNG, JPEG, BMP; not TIFF). The Radiance header is the format's text header (Greg Ward's RGBE
reader, used by Mitsuba and OpenCV alike, takes only the ``-Y height +X width`` resolution
line); PNG, JPEG and BMP headers are read by Pillow (lazily: size only); EXR's by OpenEXR.
"""
from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import OpenEXR
from PIL import Image, UnidentifiedImageError

from scenegen.assets.checks import ENVMAP_SUFFIXES, MAX_TEXTURE_PIXELS
from scenegen.quiet import decode_image, quiet_native_output

_HDR_HEADER_BYTES = 1 << 16  # the text header is a few lines; a longer one is not a Radiance file
_HDR_SIZE = re.compile(rb"^-Y (\d{1,12}) \+X (\d{1,12})$")


def hdr_size(head: bytes) -> tuple[int, int]:
    """(width, height) from the start of a Radiance .hdr file: ``#?RADIANCE`` (or ``#?RGBE``),
    header lines, a blank line, then ``-Y height +X width``; ValueError otherwise."""
    if not head.startswith((b"#?RADIANCE", b"#?RGBE")):
        raise ValueError("not a Radiance HDR file (expected '#?RADIANCE' on its first line)")
    lines = head.split(b"\n")
    try:
        blank = lines.index(b"")
        size_line = lines[blank + 1]
    except (ValueError, IndexError):
        raise ValueError("the Radiance header does not end (expected a blank line, then '-Y height +X width')") \
            from None
    m = _HDR_SIZE.match(size_line.rstrip(b"\r"))
    if m is None:
        raise ValueError(f"expected the resolution line '-Y height +X width' after the header, got "
                         f"{size_line[:40].decode('latin-1')!r}")
    return int(m.group(2)), int(m.group(1))


def header_size(path: Path) -> tuple[int, int]:
    """(width, height) of the image ``path`` from its header alone; ValueError when unreadable."""
    suffix = path.suffix.lower()
    if suffix == ".hdr":
        with open(path, "rb") as fh:
            return hdr_size(fh.read(_HDR_HEADER_BYTES))
    if suffix == ".exr":
        try:
            with quiet_native_output():
                (x0, y0), (x1, y1) = OpenEXR.File(str(path), header_only=True).header()["dataWindow"]
        except Exception as e:  # OpenEXR raises bare Exception/RuntimeError on bad files
            raise ValueError(f"not a readable EXR file ({str(e).replace(repr(str(path)), 'it')})") from None
        return int(x1) - int(x0) + 1, int(y1) - int(y0) + 1
    try:
        with warnings.catch_warnings():  # Pillow's decompression-bomb warning: the limit is ours
            warnings.simplefilter("ignore")
            with Image.open(path) as im:
                return im.size
    except (OSError, Image.DecompressionBombError, ValueError) as e:
        why = "its content is not of that format" if isinstance(e, UnidentifiedImageError) else str(e)
        raise ValueError(f"not a readable {suffix[1:].upper()} image ({why})") from None


def check_envmap(path) -> tuple[int, int]:
    """(width, height) of the environment map ``path`` once it is known to be one the renderer
    reads: a file, not empty, one of ENVMAP_SUFFIXES, at most MAX_TEXTURE_PIXELS by its header,
    decodable, finite. ValueError naming the file otherwise."""
    p = Path(path)
    what = f"environment map {str(p)!r}"
    if p.is_dir():
        raise ValueError(f"{what}: is a directory, expected an image file")
    if not p.is_file():
        raise ValueError(f"{what}: file not found")
    if p.suffix.lower() not in ENVMAP_SUFFIXES:
        raise ValueError(f"{what}: expected one of {', '.join(ENVMAP_SUFFIXES)} (the formats the renderer "
                         "reads; EXR or HDR for linear radiance)")
    if p.stat().st_size == 0:
        raise ValueError(f"{what}: the file is empty")
    try:
        w, h = header_size(p)
    except ValueError as e:
        raise ValueError(f"{what}: {e}") from None
    if w < 1 or h < 1 or w * h > MAX_TEXTURE_PIXELS:
        raise ValueError(f"{what}: {w} x {h} pixels by its header; expected 1 to {MAX_TEXTURE_PIXELS:,} pixels "
                         "(MAX_TEXTURE_PIXELS, docs/scene_spec.md 'Limits')")
    pixels = _decoded(p, what)
    if pixels.shape[:2] != (h, w):
        raise ValueError(f"{what}: the header says {w} x {h} pixels, the data {pixels.shape[1]} x {pixels.shape[0]}")
    if pixels.dtype.kind == "f" and not np.isfinite(pixels).all():
        raise ValueError(f"{what}: {int((~np.isfinite(pixels)).sum())} values are not finite (NaN or "
                         "infinite radiance); expected finite values")
    return w, h


def _decoded(p: Path, what: str) -> np.ndarray:
    """The whole image (H, W[, C]), decoded as the renderer will decode it."""
    if p.suffix.lower() == ".exr":
        try:
            with quiet_native_output():
                f = OpenEXR.File(str(p), separate_channels=True)
                channels = {name: np.asarray(ch.pixels) for name, ch in f.channels().items()}
        except Exception as e:  # OpenEXR raises bare Exception/RuntimeError on bad data
            raise ValueError(f"{what}: not a readable EXR file ({str(e).replace(repr(str(p)), 'it')})") from None
        names = [c for c in ("R", "G", "B") if c in channels] or [c for c in ("Y",) if c in channels]
        if names not in (["R", "G", "B"], ["Y"]):
            raise ValueError(f"{what}: expected channels R, G, B (or Y), got {sorted(channels)}")
        return np.stack([channels[c] for c in names], axis=-1)
    try:
        img = decode_image(p.read_bytes())
    except ValueError as e:
        raise ValueError(f"{what}: {e}") from None
    if img is None:
        raise ValueError(f"{what}: could not decode it (a damaged or truncated image)")
    return img
