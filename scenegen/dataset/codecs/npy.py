"""NPY and NPZ: ``np.save``'s and ``np.savez``'s formats, never pickles, and every array's declared
size checked before anything is allocated.

numpy allocates the array an NPY header declares before it reads a byte of the data, so a
100-byte file whose header claims 2e10 float32 would ask for 74.5 GiB. Every NPY array (a file,
or a member of an NPZ) is read here: its header is read first (``numpy.lib.format.read_magic`` /
``read_array_header_*``) and the array it declares must fit both the bytes the file holds and
:data:`MAX_ARRAY_BYTES`.
"""
from __future__ import annotations

import io
import math
import zipfile
import zlib

import numpy as np

from scenegen.dataset.files import atomic_write_bytes, read_decoded

#: Most bytes one NPY array, or all arrays of one NPZ together, may declare: 4 GiB. Why: the
#: largest truth array a spec within its limits makes is 1.5 GiB (2^26 pixels x 3 float64 hit
#: points); a header declaring more is a hostile or broken file, refused before numpy allocates.
MAX_ARRAY_BYTES = 4 << 30
_ZIP_TIME = (1980, 1, 1, 0, 0, 0)
_HEADER_READERS = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}


def encode_npy(arr) -> bytes:
    """``np.save`` bytes of ``arr`` (object arrays are refused: no pickles)."""
    buf = io.BytesIO()
    np.save(buf, np.asarray(arr), allow_pickle=False)
    return buf.getvalue()


def encode_npz(arrays) -> bytes:
    """NPZ bytes (stored, not compressed, no pickles, fixed member timestamps: numpy's ``savez``
    stamps the current time, so identical arrays give identical bytes) of a mapping name -> array,
    in its order: what ``np.load(..., allow_pickle=False)`` and :func:`decode_npz` read."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_STORED) as z:
        for key, arr in arrays.items():
            member = io.BytesIO()
            np.lib.format.write_array(member, np.asarray(arr), allow_pickle=False)
            z.writestr(zipfile.ZipInfo(f"{key}.npy", date_time=_ZIP_TIME), member.getvalue())
    return buf.getvalue()


def write_npy(path, arr) -> None:
    """Write ``arr`` in NPY format (no pickles), atomically."""
    atomic_write_bytes(path, encode_npy(arr))


def read_npy(path) -> np.ndarray:
    """Read an NPY file (pickles refused, size checked first); a ValueError names the file."""
    return read_decoded(path, decode_npy)


def checked_npy_header(f, available: int, what: str = "") -> int:
    """The byte size of the array whose NPY header starts at ``f``'s position, read (``f`` is
    left after the header) and checked: NPY 1.0/2.0, no object dtype, non-negative dimensions,
    at most :data:`MAX_ARRAY_BYTES` and at most the data bytes that follow the header
    (``available`` minus the header's length). ValueError naming ``what`` otherwise."""
    pre = f"{what}: " if what else ""
    start = f.tell()
    version = np.lib.format.read_magic(f)
    reader = _HEADER_READERS.get(version)
    if reader is None:
        raise ValueError(f"{pre}NPY format version {version[0]}.{version[1]} (expected 1.0 or 2.0)")
    shape, _fortran, dtype = reader(f)
    if dtype.hasobject:
        raise ValueError(f"{pre}an object array (it needs pickle; expected a plain numeric or text array)")
    if any(n < 0 for n in shape):
        raise ValueError(f"{pre}the header declares the shape {shape} (expected non-negative dimensions)")
    nbytes = math.prod(shape) * dtype.itemsize
    held = available - (f.tell() - start)
    if nbytes > MAX_ARRAY_BYTES or nbytes > held:
        raise ValueError(f"{pre}the header declares shape {shape} of {dtype} ({nbytes:,} bytes), but the file "
                         f"holds {max(held, 0):,} bytes of array data (expected a declared size within the file and "
                         f"at most {MAX_ARRAY_BYTES >> 30} GiB)")
    return nbytes


def decode_npy(data: bytes) -> np.ndarray:
    """Inverse of :func:`encode_npy` (pickles refused; the declared size checked first)."""
    buf = io.BytesIO(bytes(data))
    checked_npy_header(buf, len(buf.getbuffer()))
    buf.seek(0)
    return np.lib.format.read_array(buf, allow_pickle=False)


def decode_npz(data: bytes, required=()) -> dict[str, np.ndarray]:
    """``{name: array}`` of the members ``<name>.npy`` of NPZ bytes (stored or deflated, as
    ``np.savez`` / ``np.savez_compressed`` write them), in the archive's order. Every member's
    header is checked (:func:`checked_npy_header`, against the member's declared size) and the
    arrays together must fit :data:`MAX_ARRAY_BYTES` before any is read; the names in
    ``required`` must all be present. ValueError naming the member otherwise."""
    try:
        with zipfile.ZipFile(io.BytesIO(bytes(data))) as z:
            infos = z.infolist()
            names = [i.filename.removesuffix(".npy") for i in infos]
            missing = [k for k in required if k not in names]
            if missing:
                raise ValueError(f"keys {missing} missing; have {sorted(names)}")
            total = 0
            for info, name in zip(infos, names):
                what = f"member {info.filename!r}"
                if not info.filename.endswith(".npy") or names.count(name) > 1:
                    raise ValueError(f"{what}: expected members with distinct names <key>.npy")
                with z.open(info) as m:
                    total += checked_npy_header(m, info.file_size, what)
                if total > MAX_ARRAY_BYTES:
                    raise ValueError(f"{what}: the arrays declare {total:,} bytes together (expected at most "
                                     f"{MAX_ARRAY_BYTES >> 30} GiB)")
            out = {}
            for info, name in zip(infos, names):
                with z.open(info) as m:
                    out[name] = np.lib.format.read_array(m, allow_pickle=False)
            return out
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, NotImplementedError) as e:
        raise ValueError(f"not a readable NPZ archive ({e})") from None


def read_npz(path, required=()) -> dict[str, np.ndarray]:
    """:func:`decode_npz` of a file; a ValueError names the file."""
    return read_decoded(path, lambda data: decode_npz(data, required))
