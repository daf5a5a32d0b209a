"""Lossless, atomic file I/O for the dataset: JSON, PNG, EXR, NPY, hashes.

Every writer here first encodes its data to bytes in memory (``encode_*``), then writes them with
:func:`atomic_write_bytes`: a temporary file in the destination directory, ``fsync``, then
``os.replace`` onto the final name, then ``fsync`` of the directory. A reader therefore sees either
the old file or the complete new one, never a partial file, even if the process is killed
(SIGKILL) or the machine loses power mid-write. A killed write can leave a temporary file named
``.<name>.<random>.scenegen-tmp`` beside the target (see :func:`remove_stale_temp_files`).

Formats (all lossless; identical inputs give identical bytes for the same library versions):

* JSON: UTF-8, sorted keys, indent 2, trailing newline; floats in Python's shortest round-trip
  form (``repr``), so a float64 read back is bit-identical. NaN and infinities are refused (they
  are not JSON). numpy scalars and arrays are converted to Python numbers and lists.
* PNG: uint8 or uint16, (H, W) grey or (H, W, 3) RGB (converted to OpenCV's BGR on write and
  back on read).
* EXR: one part, scanlines, ZIP compression; each channel is (H, W) float32 (stored as FLOAT, never
  HALF) or uint32 (UINT). Vector quantities are stored one channel per component, named
  ``<prefix>.<component>`` (``P_world.X``, ``uv.U``): see :func:`pack_channels`.
* NPY: ``np.save`` format, no pickles.

No Mitsuba or Dr.Jit here: the reader side of the dataset must work without them.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import secrets
from pathlib import Path
from typing import Any, BinaryIO, Callable, Iterable, Mapping, Sequence

import numpy as np

__all__ = [
    "TEMP_SUFFIX",
    "atomic_write",
    "atomic_write_bytes",
    "remove_stale_temp_files",
    "sha256_bytes",
    "sha256_file",
    "encode_json",
    "write_json",
    "read_json",
    "encode_png",
    "decode_png",
    "write_png",
    "read_png",
    "encode_exr",
    "write_exr",
    "read_exr",
    "encode_npy",
    "write_npy",
    "read_npy",
    "pack_channels",
    "unpack_channels",
]

#: Suffix of the temporary files made by :func:`atomic_write` (``.<name>.<random>.scenegen-tmp``).
TEMP_SUFFIX = ".scenegen-tmp"

_HASH_CHUNK = 1 << 20  # bytes read at a time by sha256_file
_PNG_COMPRESSION = 3  # zlib level; any level is lossless, fixed so bytes don't follow cv2 defaults


# --- atomic writes ----------------------------------------------------------------------------
def _fsync_dir(directory: Path) -> None:
    """Make a rename in ``directory`` durable (no-op where directories cannot be opened)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:  # e.g. Windows
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write(path, write_fn: Callable[[BinaryIO], None]) -> None:
    """Write ``path`` atomically by calling ``write_fn(f)`` on a temporary binary file.

    The temporary file is in the same directory as ``path`` (created with its parents if needed),
    is flushed and fsync'ed, then renamed over ``path``. If ``write_fn`` raises, the temporary file
    is removed, ``path`` is left exactly as it was (old content or absent) and the error propagates.
    New files get the usual permissions (0o666 minus the umask).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}{TEMP_SUFFIX}"
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    try:
        with os.fdopen(fd, "wb") as f:
            write_fn(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise
    _fsync_dir(path.parent)


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_write`)."""
    data = bytes(data) if not isinstance(data, bytes) else data
    atomic_write(path, lambda f: f.write(data))


def remove_stale_temp_files(root) -> list[Path]:
    """Delete temporary files left under ``root`` by killed :func:`atomic_write` calls.

    Only files named ``.<name>.<random>.scenegen-tmp`` are touched. Call it only when no writer is
    running on ``root``. Returns the removed paths.
    """
    removed = []
    for p in sorted(Path(root).rglob(f".*{TEMP_SUFFIX}")):
        if p.is_file():
            p.unlink()
            removed.append(p)
    return removed


# --- hashes -----------------------------------------------------------------------------------
def sha256_bytes(data: bytes) -> str:
    """Lower-case hex SHA-256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def sha256_file(path) -> str:
    """Lower-case hex SHA-256 of the file's bytes (read in 1 MiB chunks)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(_HASH_CHUNK):
            h.update(chunk)
    return h.hexdigest()


# --- JSON -------------------------------------------------------------------------------------
def _json_default(o: Any):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.bool_):
        return bool(o)
    if isinstance(o, np.integer):
        return int(o)
    if isinstance(o, np.floating):
        return float(o)  # exact for float16/32/64; repr then round-trips the float64
    if isinstance(o, os.PathLike):
        return Path(o).as_posix()
    if isinstance(o, (set, frozenset)):
        raise TypeError("sets have no stable order; pass a sorted list")
    raise TypeError(f"object of type {type(o).__name__} is not JSON serialisable")


def encode_json(obj: Any) -> bytes:
    """Canonical JSON bytes: sorted keys, indent 2, ``repr`` floats, UTF-8, trailing newline.

    Raises ValueError for NaN/inf (not valid JSON) and TypeError for unsupported objects.
    """
    try:
        text = json.dumps(obj, sort_keys=True, indent=2, ensure_ascii=False, allow_nan=False,
                          default=_json_default)
    except ValueError as e:
        raise ValueError(f"cannot write JSON: {e} (NaN and infinities are not JSON)") from e
    return (text + "\n").encode("utf-8")


def write_json(path, obj: Any) -> None:
    """Write ``obj`` as canonical JSON (:func:`encode_json`), atomically."""
    atomic_write_bytes(path, encode_json(obj))


def read_json(path) -> Any:
    with open(path, "rb") as f:
        return json.loads(f.read().decode("utf-8"))


# --- PNG --------------------------------------------------------------------------------------
def encode_png(img) -> bytes:
    """PNG bytes of a uint8/uint16 image, (H, W) grey or (H, W, 3) RGB."""
    import cv2

    img = np.asarray(img)
    if img.dtype not in (np.uint8, np.uint16):
        raise TypeError(f"PNG images must be uint8 or uint16, got {img.dtype}")
    if not (img.ndim == 2 or (img.ndim == 3 and img.shape[2] == 3)) or 0 in img.shape:
        raise ValueError(f"PNG images must be (H, W) or (H, W, 3) and non-empty, got {img.shape}")
    if img.ndim == 3:
        img = img[..., ::-1]  # RGB -> BGR for OpenCV
    ok, buf = cv2.imencode(".png", np.ascontiguousarray(img),
                           [cv2.IMWRITE_PNG_COMPRESSION, _PNG_COMPRESSION])
    if not ok:
        raise RuntimeError("cv2.imencode failed to encode the PNG")
    return buf.tobytes()


def decode_png(data: bytes) -> np.ndarray:
    """Inverse of :func:`encode_png`: (H, W) or (H, W, 3) RGB, dtype as stored."""
    import cv2

    img = cv2.imdecode(np.frombuffer(data, dtype=np.uint8), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise ValueError("not a readable PNG")
    if img.ndim == 3:
        if img.shape[2] == 3:
            img = cv2.cvtColor(img, cv2.COLOR_BGR2RGB)
        elif img.shape[2] == 4:
            img = cv2.cvtColor(img, cv2.COLOR_BGRA2RGBA)
    return img


def write_png(path, img) -> None:
    """Write a uint8/uint16 (H, W) or (H, W, 3) RGB image as PNG, atomically."""
    atomic_write_bytes(path, encode_png(img))


def read_png(path) -> np.ndarray:
    """Read a PNG: (H, W) grey or (H, W, 3) RGB, dtype (uint8/uint16) as stored."""
    try:
        return decode_png(Path(path).read_bytes())
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None


# --- EXR --------------------------------------------------------------------------------------
_EXR_DTYPES = (np.dtype(np.float32), np.dtype(np.uint32))


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


def encode_exr(channels: Mapping[str, np.ndarray]) -> bytes:
    """EXR bytes (one part, scanlines, ZIP) of named (H, W) float32 / uint32 channels.

    Values are stored bit-exactly (float32 as FLOAT, NaN and infinities included; uint32 as UINT).
    The file lists channels in alphabetical order (an EXR rule).
    """
    import OpenEXR

    chans = _checked_exr_channels(channels)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    buf = io.BytesIO()
    OpenEXR.File(header, chans).write(buf)
    return buf.getvalue()


def write_exr(path, channels: Mapping[str, np.ndarray]) -> None:
    """Write named (H, W) float32/uint32 channels to a ZIP-compressed EXR, atomically."""
    atomic_write_bytes(path, encode_exr(channels))


def read_exr(path) -> dict[str, np.ndarray]:
    """Read every channel of a one-part EXR: ``{name: (H, W) array}`` in the file's (alphabetical)
    order; FLOAT -> float32, UINT -> uint32 (HALF -> float16), values bit-exact."""
    import OpenEXR

    path = Path(path)
    try:
        f = OpenEXR.File(str(path), separate_channels=True)
    except Exception as e:  # OpenEXR raises a bare Exception/RuntimeError on bad files
        raise ValueError(f"{path}: not a readable EXR file ({e})") from None
    return {name: np.ascontiguousarray(ch.pixels) for name, ch in f.channels().items()}


# --- NPY --------------------------------------------------------------------------------------
def encode_npy(arr) -> bytes:
    """``np.save`` bytes of ``arr`` (object arrays are refused: no pickles)."""
    buf = io.BytesIO()
    np.save(buf, np.asarray(arr), allow_pickle=False)
    return buf.getvalue()


def write_npy(path, arr) -> None:
    """Write ``arr`` in NPY format (no pickles), atomically."""
    atomic_write_bytes(path, encode_npy(arr))


def read_npy(path) -> np.ndarray:
    return np.load(path, allow_pickle=False)


# --- vector <-> channels ------------------------------------------------------------------------
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
