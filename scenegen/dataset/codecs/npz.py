"""NPZ: a zip of NPY members, pickle-free, with fixed member timestamps (numpy's ``savez`` stamps
the current time), so identical arrays give identical bytes; read back with every member's
declared shape checked against a size limit before anything is allocated."""
from __future__ import annotations

import io
import zipfile

import numpy as np

_ZIP_TIME = (1980, 1, 1, 0, 0, 0)
#: What one NPZ member may declare (bytes), checked from its NPY header before it is read: a
#: crafted header cannot make a reader allocate what the file does not hold.
MAX_MEMBER_BYTES = 1 << 31


def encode_npz(arrays) -> bytes:
    """NPZ bytes (stored, not compressed, no pickles, fixed member timestamps) of a mapping
    name -> array, in its order: what ``np.load(..., allow_pickle=False)`` reads."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_STORED) as z:
        for key, arr in arrays.items():
            member = io.BytesIO()
            np.lib.format.write_array(member, np.asarray(arr), allow_pickle=False)
            z.writestr(zipfile.ZipInfo(f"{key}.npy", date_time=_ZIP_TIME), member.getvalue())
    return buf.getvalue()


def decode_npz(data: bytes, *, max_member_bytes: int = MAX_MEMBER_BYTES) -> dict[str, np.ndarray]:
    """{name: array} of NPZ bytes. ValueError (naming the member) for a file that is not an NPZ,
    a pickled or object member, or a member whose header declares more than
    ``max_member_bytes`` or more than it holds."""
    try:
        z = zipfile.ZipFile(io.BytesIO(bytes(data)))
    except (zipfile.BadZipFile, OSError) as e:
        raise ValueError(f"not an NPZ archive ({e})") from None
    out = {}
    with z:
        for info in z.infolist():
            if not info.filename.endswith(".npy"):
                raise ValueError(f"member {info.filename!r} is not an .npy array")
            name = info.filename[:-4]
            try:
                with z.open(info) as f:
                    version = np.lib.format.read_magic(f)
                    read_header = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                                   else np.lib.format.read_array_header_2_0)
                    shape, _, dtype = read_header(f)
                    if dtype.hasobject:
                        raise ValueError("holds Python objects (pickles are refused)")
                    declared = int(np.prod(shape, dtype=object)) * dtype.itemsize
                    if declared > min(max_member_bytes, info.file_size):
                        what = (f"the limit of {max_member_bytes}" if declared > max_member_bytes
                                else f"the {info.file_size} bytes the member holds")
                        raise ValueError(f"its header declares {shape} {dtype} ({declared} bytes), more than {what}")
                with z.open(info) as f:
                    out[name] = np.lib.format.read_array(f, allow_pickle=False)
            except (ValueError, OSError, zipfile.BadZipFile, EOFError) as e:
                raise ValueError(f"member {name!r}: {e}") from None
    return out
