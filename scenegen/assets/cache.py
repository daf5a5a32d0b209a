"""Procedural assets (textures, blob meshes) cached by content hash, in this process and on disk.

A natural 512 px texture takes about 0.5 s to make and a subdivision-5 blob about 0.1 s, in
every process that builds the scene (each Dask worker, each variant, each resumed run). The
result is a pure function of its parameters, seed and code, so it is cached under
``sha256(kind, parameters, the source of scenegen.assets and scenegen.geometry, the numpy,
OpenCV and trimesh versions)``: any change to the code or the libraries that make it misses.

On disk: ``$SCENEGEN_CACHE_DIR`` (default ``$XDG_CACHE_HOME/scenegen/assets`` or
``~/.cache/scenegen/assets``; ``off`` disables it), one ``.npz`` per asset holding its arrays and
their SHA-256, written atomically; an unreadable or mismatching file is made again. The arrays
come back read-only and bitwise identical to freshly made ones (tests/scenegen/assets/test_cache.py).
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import secrets
import zipfile
from collections import OrderedDict
from collections.abc import Callable
from functools import lru_cache
from importlib import metadata
from pathlib import Path

import numpy as np

CACHE_ENV = "SCENEGEN_CACHE_DIR"
FORMAT = 1
MEMORY_ENTRIES = 16  # assets kept in this process (a 512 px texture is 3 MiB)
_MEMORY: OrderedDict[str, dict[str, np.ndarray]] = OrderedDict()
_PACKAGES = ("scenegen.assets", "scenegen.geometry")  # the code an asset is made by


def cache_dir() -> Path | None:
    """The on-disk cache folder, or None if disabled (``SCENEGEN_CACHE_DIR=off``)."""
    v = os.environ.get(CACHE_ENV)
    if v is not None:
        return None if v.strip().lower() in ("", "off", "0", "none", "false") else Path(v)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "scenegen" / "assets"


@lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-256 over the source files of the packages that make assets, and the library versions."""
    h = hashlib.sha256()
    root = Path(__file__).resolve().parents[1]  # the scenegen package
    for pkg in _PACKAGES:
        for p in sorted((root / pkg.split(".", 1)[1]).rglob("*.py")):
            h.update(p.relative_to(root).as_posix().encode() + b"\0" + p.read_bytes() + b"\0")
    for dist in ("numpy", "opencv-python-headless", "opencv-python", "trimesh"):
        try:
            h.update(f"{dist}={metadata.version(dist)};".encode())
        except metadata.PackageNotFoundError:
            h.update(f"{dist}=-;".encode())
    return h.hexdigest()


def asset_key(kind: str, params) -> str:
    """The content hash of an asset: its kind and parameters (JSON-able), the code fingerprint."""
    doc = {"format": FORMAT, "kind": kind, "params": params, "code": code_fingerprint()}
    return hashlib.sha256(json.dumps(doc, sort_keys=True, default=repr).encode()).hexdigest()


def _digest(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(f"{name}:{a.dtype.str}:{a.shape};".encode() + a.tobytes())
    return h.hexdigest()


def _read(path: Path) -> dict[str, np.ndarray] | None:
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None
    stored = arrays.pop("__sha256__", None)
    if stored is None or str(stored) != _digest(arrays):
        return None
    return arrays


def _write(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Best effort: a cache that cannot be written is just not used."""
    buf = io.BytesIO()
    np.savez(buf, __sha256__=np.array(_digest(arrays)), **arrays)
    tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp"
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_bytes(buf.getvalue())
        os.replace(tmp, path)
    except OSError:
        try:
            tmp.unlink()
        except OSError:
            pass


def cached_arrays(kind: str, params, make: Callable[[], dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """``make()`` (a dict of arrays), or the cached result of an earlier call with the same kind,
    parameters and code; arrays are read-only."""
    key = asset_key(kind, params)
    hit = _MEMORY.get(key)
    if hit is not None:
        _MEMORY.move_to_end(key)
        return dict(hit)
    folder = cache_dir()
    path = None if folder is None else folder / f"{kind}-{key}.npz"
    arrays = _read(path) if path is not None and path.is_file() else None
    if arrays is None:
        arrays = {k: np.asarray(v) for k, v in make().items()}
        if path is not None:
            _write(path, arrays)
    for a in arrays.values():
        a.setflags(write=False)
    _MEMORY[key] = arrays
    while len(_MEMORY) > MEMORY_ENTRIES:
        _MEMORY.popitem(last=False)
    return dict(arrays)
