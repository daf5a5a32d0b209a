"""DNG (Adobe Digital Negative 1.4): a raw Bayer mosaic with the tags a raw decoder needs.

Written here with numpy and ``struct`` (no TIFF library), so the bytes are fixed by this module
alone: a little-endian TIFF with one IFD (IFD 0, ``NewSubFileType`` 0: the raw image itself, no
preview), uncompressed 16-bit samples in one strip, and these tags (DNG 1.4 spec, chapter 4):

=====================  =====  ===========================================================
tag                    code   value
=====================  =====  ===========================================================
PhotometricInterp.      262   32803 (CFA)
Orientation             274   1 (row 0 at the top, column 0 at the left: array ``[v, u]``)
CFARepeatPatternDim   33421   2, 2
CFAPattern            33422   the 2x2 block row by row, 0 = R, 1 = G, 2 = B (``RGGB`` = 0 1 1 2)
DNGVersion            50706   1.4.0.0 (DNGBackwardVersion 50707: 1.1.0.0)
UniqueCameraModel     50708   the camera's name
CFAPlaneColor         50710   0, 1, 2 (R, G, B);  CFALayout 50711: 1 (rectangular)
BlackLevel            50714   one value for every pixel (BlackLevelRepeatDim 50713: 1, 1)
WhiteLevel            50717   the largest sample the sensor can record
ColorMatrix1          50721   XYZ -> camera RGB, 3x3 SRATIONAL (CalibrationIlluminant1 50778: 21 = D65)
AsShotNeutral         50728   camera RGB of a neutral surface as shot (1 / white-balance gains)
=====================  =====  ===========================================================

Rationals are written as ``round(x * 10^6) / 10^6``; :func:`decode_dng` returns what the file
holds (the exact floats are the writer's to keep elsewhere, e.g. cameras.json).
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from scenegen.dataset.files import atomic_write_bytes, read_decoded

#: CFAPlaneColor codes of the DNG spec: 0 red, 1 green, 2 blue.
CFA_COLOURS = "RGB"
#: CalibrationIlluminant code (EXIF LightSource) of D65.
ILLUMINANT_D65 = 21
RATIONAL_DENOMINATOR = 1_000_000
SOFTWARE = "scenegen"

_BYTE, _ASCII, _SHORT, _LONG, _RATIONAL, _SRATIONAL = 1, 2, 3, 4, 5, 10
_TYPE_SIZE = {_BYTE: 1, _ASCII: 1, _SHORT: 2, _LONG: 4, _RATIONAL: 8, _SRATIONAL: 8}
_TYPE_FORMAT = {_BYTE: "B", _ASCII: "B", _SHORT: "H", _LONG: "I", _RATIONAL: "I", _SRATIONAL: "i"}
T = dict(new_subfile_type=254, width=256, height=257, bits=258, compression=259,
         photometric=262, make=271, model=272, strip_offsets=273, orientation=274, samples=277,
         rows_per_strip=278, strip_byte_counts=279, planar=284, software=305,
         cfa_repeat=33421, cfa_pattern=33422, dng_version=50706, dng_backward=50707,
         unique_model=50708, cfa_plane_color=50710, cfa_layout=50711, black_repeat=50713,
         black_level=50714, white_level=50717, color_matrix1=50721, as_shot_neutral=50728,
         illuminant1=50778)
PHOTOMETRIC_CFA = 32803


@dataclass(frozen=True, eq=False)
class DngRaw:
    """What a DNG of this module holds."""

    mosaic: np.ndarray  # (H, W) uint16 CFA samples, array [v, u], DN
    cfa_pattern: str  # top-left 2x2 block row by row, e.g. 'RGGB'
    black_level_dn: float  # DN of zero signal
    white_level_dn: int  # largest recordable DN
    as_shot_neutral: tuple[float, float, float]  # camera R, G, B of a neutral surface
    color_matrix: np.ndarray  # (3, 3) XYZ -> camera RGB under D65 (ColorMatrix1)
    camera_model: str = "scenegen"  # UniqueCameraModel (and Model)
    make: str = "scenegen"
    orientation: int = 1


def _ascii(s: str) -> list[int]:
    return list(s.encode("ascii", "replace") + b"\0")


def _rationals(values, signed: bool) -> list[int]:
    out = []
    for x in np.asarray(values, dtype=np.float64).ravel():
        if not np.isfinite(x):
            raise ValueError(f"DNG rationals must be finite, got {x}")
        num = int(round(float(x) * RATIONAL_DENOMINATOR))
        lim = 2**31 - 1 if signed else 2**32 - 1
        if num > lim or (num < 0 and not signed) or num < -lim:
            raise ValueError(f"DNG rational {x} out of range")
        out += [num, RATIONAL_DENOMINATOR]
    return out


def encode_dng(raw: DngRaw) -> bytes:
    """DNG bytes of a CFA mosaic and its metadata (see the module docstring)."""
    m = np.asarray(raw.mosaic)
    if m.dtype != np.uint16 or m.ndim != 2 or 0 in m.shape:
        raise ValueError(f"a DNG mosaic must be a non-empty (H, W) uint16 array, got {m.dtype} {m.shape}")
    if not (isinstance(raw.cfa_pattern, str) and len(raw.cfa_pattern) == 4
            and set(raw.cfa_pattern) <= set(CFA_COLOURS)):
        raise ValueError(f"CFA pattern must be 4 letters of R, G, B (the 2x2 block row by row), "
                         f"got {raw.cfa_pattern!r}")
    if not 0 <= raw.black_level_dn < raw.white_level_dn <= 65535:
        raise ValueError(f"expected 0 <= black level < white level <= 65535, got "
                         f"{raw.black_level_dn}, {raw.white_level_dn}")
    cm = np.asarray(raw.color_matrix, dtype=np.float64)
    if cm.shape != (3, 3):
        raise ValueError(f"ColorMatrix1 must be 3x3, got {cm.shape}")
    H, W = m.shape
    pixels = np.ascontiguousarray(m.astype("<u2")).tobytes()
    black = float(raw.black_level_dn)
    entries = [  # (tag, type, values)
        (T["new_subfile_type"], _LONG, [0]), (T["width"], _LONG, [W]), (T["height"], _LONG, [H]),
        (T["bits"], _SHORT, [16]), (T["compression"], _SHORT, [1]),
        (T["photometric"], _SHORT, [PHOTOMETRIC_CFA]), (T["make"], _ASCII, _ascii(raw.make)),
        (T["model"], _ASCII, _ascii(raw.camera_model)), (T["strip_offsets"], _LONG, [0]),
        (T["orientation"], _SHORT, [int(raw.orientation)]), (T["samples"], _SHORT, [1]),
        (T["rows_per_strip"], _LONG, [H]), (T["strip_byte_counts"], _LONG, [len(pixels)]),
        (T["planar"], _SHORT, [1]), (T["software"], _ASCII, _ascii(SOFTWARE)),
        (T["cfa_repeat"], _SHORT, [2, 2]),
        (T["cfa_pattern"], _BYTE, [CFA_COLOURS.index(c) for c in raw.cfa_pattern]),
        (T["dng_version"], _BYTE, [1, 4, 0, 0]), (T["dng_backward"], _BYTE, [1, 1, 0, 0]),
        (T["unique_model"], _ASCII, _ascii(raw.camera_model)),
        (T["cfa_plane_color"], _BYTE, [0, 1, 2]), (T["cfa_layout"], _SHORT, [1]),
        (T["black_repeat"], _SHORT, [1, 1]),
        (T["black_level"], *((_LONG, [int(black)]) if black.is_integer()
                             else (_RATIONAL, _rationals([black], False)))),
        (T["white_level"], _LONG, [int(raw.white_level_dn)]),
        (T["color_matrix1"], _SRATIONAL, _rationals(cm, True)),
        (T["as_shot_neutral"], _RATIONAL, _rationals(raw.as_shot_neutral, False)),
        (T["illuminant1"], _SHORT, [ILLUMINANT_D65]),
    ]
    entries.sort(key=lambda e: e[0])
    ifd_offset = 8
    ifd_size = 2 + 12 * len(entries) + 4
    data_offset = ifd_offset + ifd_size
    blobs: list[bytes] = []
    packed_entries = []
    for tag, typ, values in entries:
        count = len(values) // 2 if typ in (_RATIONAL, _SRATIONAL) else len(values)
        payload = struct.pack("<" + _TYPE_FORMAT[typ] * len(values), *values)
        packed_entries.append([tag, typ, count, payload])
    # out-of-line values after the IFD (word aligned), then the pixels
    offset = data_offset
    for e in packed_entries:
        if len(e[3]) > 4:
            blobs.append(e[3] + b"\0" * (len(e[3]) % 2))
            e.append(offset)
            offset += len(blobs[-1])
    pixel_offset = offset
    ifd = [struct.pack("<H", len(packed_entries))]
    for e in packed_entries:
        tag, typ, count, payload = e[:4]
        if tag == T["strip_offsets"]:
            payload = struct.pack("<I", pixel_offset)
        value = struct.pack("<I", e[4]) if len(payload) > 4 else payload.ljust(4, b"\0")
        ifd.append(struct.pack("<HHI", tag, typ, count) + value)
    ifd.append(struct.pack("<I", 0))  # no further IFD
    return b"".join([b"II*\0", struct.pack("<I", ifd_offset), *ifd, *blobs, pixels])


def _read_ifd(data: bytes) -> dict[int, tuple]:
    if len(data) < 8 or data[:4] not in (b"II*\0", b"MM\0*"):
        raise ValueError("not a TIFF/DNG file (bad header)")
    e = "<" if data[:2] == b"II" else ">"
    (ifd_offset,) = struct.unpack_from(e + "I", data, 4)
    (n,) = struct.unpack_from(e + "H", data, ifd_offset)
    tags = {}
    for i in range(n):
        tag, typ, count, raw_value = struct.unpack_from(e + "HHI4s", data, ifd_offset + 2 + 12 * i)
        if typ not in _TYPE_SIZE:
            continue  # a type this reader does not need
        nvals = count * (2 if typ in (_RATIONAL, _SRATIONAL) else 1)
        size = _TYPE_SIZE[typ] * count
        src = raw_value if size <= 4 else data[struct.unpack(e + "I", raw_value)[0]:][:size]
        if len(src) < size:
            raise ValueError(f"DNG tag {tag}: value runs past the end of the file")
        vals = struct.unpack(e + _TYPE_FORMAT[typ] * nvals, src[:size])
        if typ in (_RATIONAL, _SRATIONAL):
            vals = tuple(vals[k] / vals[k + 1] for k in range(0, len(vals), 2))
        tags[tag] = (typ, vals, e)
    return tags


def decode_dng(data: bytes) -> DngRaw:
    """Inverse of :func:`encode_dng` (rationals as the file holds them); ValueError if the file
    is not an uncompressed 16-bit CFA DNG."""
    data = bytes(data)
    tags = _read_ifd(data)

    def get(name, n=None):
        if T[name] not in tags:
            raise ValueError(f"DNG: missing tag {name} ({T[name]})")
        typ, vals, _ = tags[T[name]]
        if typ == _ASCII:
            return bytes(vals).split(b"\0")[0].decode("ascii", "replace")
        if n is not None and len(vals) != n:
            raise ValueError(f"DNG: tag {name} has {len(vals)} values, expected {n}")
        return vals

    if get("photometric", 1)[0] != PHOTOMETRIC_CFA:
        raise ValueError("DNG: not a CFA image (PhotometricInterpretation != 32803)")
    if get("compression", 1)[0] != 1 or get("bits", 1)[0] != 16 or get("samples", 1)[0] != 1:
        raise ValueError("DNG: only uncompressed 16-bit single-sample mosaics are read here")
    if tuple(get("cfa_repeat", 2)) != (2, 2):
        raise ValueError("DNG: only 2x2 CFA patterns are read here")
    colours = tuple(get("cfa_plane_color", 3)) if T["cfa_plane_color"] in tags else (0, 1, 2)
    pattern = "".join(CFA_COLOURS[colours.index(c)] for c in get("cfa_pattern", 4))
    W, H = get("width", 1)[0], get("height", 1)[0]
    e = tags[T["width"]][2]
    offsets, counts = get("strip_offsets"), get("strip_byte_counts")
    buf = b"".join(data[o:o + c] for o, c in zip(offsets, counts))
    if len(buf) != 2 * W * H:
        raise ValueError(f"DNG: {len(buf)} pixel bytes for a {W}x{H} 16-bit image")
    mosaic = np.frombuffer(buf, dtype=e + "u2").reshape(H, W).astype(np.uint16)
    black = get("black_level")
    if len(set(black)) != 1:
        raise ValueError("DNG: only one black level for all pixels is read here")
    return DngRaw(mosaic=mosaic, cfa_pattern=pattern, black_level_dn=float(black[0]),
                  white_level_dn=int(get("white_level", 1)[0]),
                  as_shot_neutral=tuple(float(v) for v in get("as_shot_neutral", 3)),
                  color_matrix=np.array(get("color_matrix1", 9), dtype=np.float64).reshape(3, 3),
                  camera_model=get("unique_model"), make=get("make"),
                  orientation=int(get("orientation", 1)[0]))


def write_dng(path, raw: DngRaw) -> None:
    """Write :func:`encode_dng` bytes atomically."""
    atomic_write_bytes(path, encode_dng(raw))


def read_dng(path) -> DngRaw:
    """Read a DNG written by :func:`write_dng`; a ValueError names the file."""
    return read_decoded(path, decode_dng)
