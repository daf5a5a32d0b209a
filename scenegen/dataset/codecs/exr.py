"""OpenEXR: one part, scanlines, ZIP compression (or another lossless one of :data:`EXR_COMPRESSIONS`
for a view's files, ``render.exr_compression``); each channel is (H, W) float32 (stored as FLOAT,
never HALF) or uint32 (UINT), bit-exact. Vector quantities are stored one channel per component,
named ``<prefix>.<component>`` (``P_world.X``, ``uv.U``): :func:`pack_channels`.
"""
from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Iterable, Mapping, Sequence

import numpy as np
import OpenEXR

from scenegen.dataset.files import atomic_write_bytes
from scenegen.quiet import quiet_native_output

_EXR_DTYPES = (np.dtype(np.float32), np.dtype(np.uint32))


@dataclass(frozen=True)
class ExrCompression:
    """A lossless OpenEXR compression a dataset's view files may use, and who reads it back."""

    openexr_name: str  # the OpenEXR binding's constant, ``<name>_COMPRESSION``
    opencv_reads: bool  # OpenCV 4.14 (its bundled OpenEXR) decodes it (R, G, B files: the linear image)


#: ``render.exr_compression`` -> the compression (all lossless, bit-exact for FLOAT and UINT;
#: measured in docs/performance.md). ZIP is the format's default; ZSTD needs OpenEXR >= 3.4.
EXR_COMPRESSIONS = MappingProxyType({
    "zip": ExrCompression("ZIP", opencv_reads=True),
    "zips": ExrCompression("ZIPS", opencv_reads=True),
    "rle": ExrCompression("RLE", opencv_reads=True),
    "none": ExrCompression("NO", opencv_reads=True),
    "zstd": ExrCompression("ZSTD", opencv_reads=False),
})
DEFAULT_EXR_COMPRESSION = "zip"


def _checked_exr_channels(channels: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    if not channels:
        raise ValueError("an EXR file needs at least one channel")
    out, shape = {}, None
    for name, arr in channels.items():
        if not isinstance(name, str) or not name or not name.isascii() or not name.isprintable():
            raise ValueError(f"EXR channel names must be non-empty printable ASCII, got {name!r}")
        arr = np.asarray(arr)
        if arr.dtype not in _EXR_DTYPES:
            raise TypeError(
                f"EXR channel {name!r}: dtype must be float32 or uint32 (stored losslessly as FLOAT"
                f" or UINT), got {arr.dtype}; cast explicitly if that is what you mean")
        if arr.ndim != 2 or 0 in arr.shape:
            raise ValueError(f"EXR channel {name!r} must be a non-empty (H, W) array, got {arr.shape}")
        if shape is not None and arr.shape != shape:
            raise ValueError(f"EXR channel {name!r} has shape {arr.shape}, others {shape}")
        shape = arr.shape
        out[name] = np.ascontiguousarray(arr)
    return out


def encode_exr(channels: Mapping[str, np.ndarray], compression: str = DEFAULT_EXR_COMPRESSION) -> bytes:
    """EXR bytes (one part, scanlines, ZIP or ``compression`` of :data:`EXR_COMPRESSIONS`) of
    named (H, W) float32 / uint32 channels.

    Values are stored bit-exactly (float32 as FLOAT, NaN and infinities included; uint32 as UINT).
    The file lists channels in alphabetical order (an EXR rule).
    """
    if compression not in EXR_COMPRESSIONS:
        raise ValueError(f"EXR compression must be one of {sorted(EXR_COMPRESSIONS)}, got {compression!r}")
    chans = _checked_exr_channels(channels)
    comp = getattr(OpenEXR, f"{EXR_COMPRESSIONS[compression].openexr_name}_COMPRESSION")
    header = {"compression": comp, "type": OpenEXR.scanlineimage}
    buf = io.BytesIO()
    OpenEXR.File(header, chans).write(buf)
    return buf.getvalue()


def write_exr(path, channels: Mapping[str, np.ndarray]) -> None:
    """Write named (H, W) float32/uint32 channels to a ZIP-compressed EXR, atomically."""
    atomic_write_bytes(path, encode_exr(channels))


def _read(source, what: str, header_only: bool = False):
    """OpenEXR.File of ``source`` (a path or a stream) with its channels read, quietly
    (:mod:`scenegen.quiet`); OpenEXR's errors (bare Exception/RuntimeError, also from the pixel data,
    read lazily) become a ValueError naming ``what``."""
    try:
        with quiet_native_output():
            f = OpenEXR.File(source, separate_channels=True, header_only=header_only)
            channels = None if header_only else {name: np.ascontiguousarray(ch.pixels)
                                                 for name, ch in f.channels().items()}
    except Exception as e:  # OpenEXR raises bare Exception/RuntimeError on bad data
        why = str(e).replace(f"'{source}'" if isinstance(source, str) else "'<python_buffer>'", "it")
        raise ValueError(f"{what}not a readable EXR file ({why})") from None  # the path named once
    return f, channels


def decode_exr(data: bytes) -> dict[str, np.ndarray]:
    """Every channel of one-part EXR bytes: ``{name: (H, W) array}`` in the file's (alphabetical)
    order; FLOAT -> float32, UINT -> uint32 (HALF -> float16), values bit-exact."""
    return _read(io.BytesIO(bytes(data)), "")[1]


def read_exr(path) -> dict[str, np.ndarray]:
    """Every channel of a one-part EXR file (see :func:`decode_exr`)."""
    return _read(str(Path(path)), f"{Path(path)}: ")[1]


def _components_for(n: int, components: Sequence[str] | None) -> tuple[str, ...]:
    if components is None:
        defaults = {2: ("U", "V"), 3: ("X", "Y", "Z")}
        if n not in defaults:
            raise ValueError(f"no default component names for {n} components; pass components=")
        return defaults[n]
    components = tuple(components)
    if len(components) != n:
        raise ValueError(f"{len(components)} component names for {n} components")
    return components


def _channel_name(prefix: str, component: str) -> str:
    return f"{prefix}.{component}" if prefix else component


def pack_channels(prefix: str, array, components: Sequence[str] | None = None) -> dict[str, np.ndarray]:
    """Split an (H, W, C) array into C named (H, W) channels ``<prefix>.<component>``.

    ``components`` defaults to X, Y, Z for C = 3 and U, V for C = 2; an empty ``prefix`` gives bare
    names (``pack_channels("", rgb, "RGB")`` -> R, G, B).
    """
    array = np.asarray(array)
    if array.ndim != 3:
        raise ValueError(f"expected an (H, W, C) array, got shape {array.shape}")
    comps = _components_for(array.shape[2], components)
    return {_channel_name(prefix, c): np.ascontiguousarray(array[..., i]) for i, c in enumerate(comps)}


def unpack_channels(channels: Mapping[str, np.ndarray], prefix: str,
                    components: Iterable[str] = ("X", "Y", "Z")) -> np.ndarray:
    """Stack channels ``<prefix>.<component>`` into an (H, W, C) array (inverse of
    :func:`pack_channels`). Raises KeyError naming a missing channel."""
    names = [_channel_name(prefix, c) for c in components]
    missing = [n for n in names if n not in channels]
    if missing:
        raise KeyError(f"missing channel(s) {missing}; have {sorted(channels)}")
    return np.stack([np.asarray(channels[n]) for n in names], axis=-1)
