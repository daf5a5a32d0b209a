"""The file formats of a dataset, encode and decode together, one module per format.

Every ``encode_*`` returns bytes (writes nothing); every ``write_*`` writes those bytes with
:func:`scenegen.dataset.files.atomic_write_bytes`; every ``decode_*``/``read_*`` inverts its
encoder exactly (lossless formats only) and raises ValueError naming what is wrong (and the file,
for ``read_*``). Identical inputs give identical bytes for the same library versions.

* :mod:`.json`: canonical JSON.
* :mod:`.png`: uint8/uint16 grey or RGB images.
* :mod:`.exr`: named float32/uint32 channels; vectors as ``<prefix>.<component>``.
* :mod:`.npy`: arrays (``.npy``) and archives of arrays (``.npz``) without pickles, sizes checked.
* :mod:`.pfm`: Middlebury/ETH3D float maps.
* :mod:`.kitti`: KITTI uint16 disparity PNGs; :mod:`.kitti_flow`: KITTI 16-bit RGB flow PNGs.
* :mod:`.flo`: Middlebury optical flow.
* :mod:`.sintel`: MPI-Sintel depth (``.dpt``) and camera (``.cam``) files.
* :mod:`.tracks`: TAP-Vid-style point tracks as a pickle-free NPZ.
* :mod:`.dng`: raw Bayer mosaics as DNG (own TIFF writer and reader, no TIFF library).
"""
from scenegen.dataset.codecs.dng import DngRaw, decode_dng, encode_dng, read_dng, write_dng
from scenegen.dataset.codecs.exr import decode_exr, encode_exr, pack_channels, read_exr, unpack_channels, write_exr
from scenegen.dataset.codecs.flo import decode_flo, encode_flo
from scenegen.dataset.codecs.json import decode_json, encode_json, read_json, write_json
from scenegen.dataset.codecs.kitti import (
                                         decode_kitti_disparity,
                                         disparity_from_kitti_array,
                                         encode_kitti_disparity,
                                         kitti_disparity_array,
)
from scenegen.dataset.codecs.kitti_flow import decode_kitti_flow_png, encode_kitti_flow_png
from scenegen.dataset.codecs.npy import decode_npy, decode_npz, encode_npy, encode_npz, read_npy, read_npz, write_npy
from scenegen.dataset.codecs.pfm import decode_pfm, encode_pfm, read_pfm, write_pfm
from scenegen.dataset.codecs.png import decode_png, encode_png, read_png, write_png
from scenegen.dataset.codecs.sintel import decode_cam, decode_dpt, encode_cam, encode_dpt
from scenegen.dataset.codecs.tracks import (
    TRACK_KEYS, TrackSet, decode_tracks, encode_tracks, read_tracks, write_tracks,
)

__all__ = [
    "DngRaw", "decode_dng", "encode_dng", "read_dng", "write_dng",
    "decode_exr", "encode_exr", "pack_channels", "read_exr", "unpack_channels", "write_exr",
    "decode_flo", "encode_flo", "decode_json", "encode_json", "read_json", "write_json",
    "decode_kitti_disparity", "disparity_from_kitti_array", "encode_kitti_disparity", "kitti_disparity_array",
    "decode_kitti_flow_png", "encode_kitti_flow_png",
    "decode_npy", "decode_npz", "encode_npy", "encode_npz", "read_npy", "read_npz", "write_npy",
    "decode_pfm", "encode_pfm", "read_pfm", "write_pfm",
    "decode_png", "encode_png", "read_png", "write_png", "decode_cam", "decode_dpt", "encode_cam", "encode_dpt",
    "TRACK_KEYS", "TrackSet", "decode_tracks", "encode_tracks", "read_tracks", "write_tracks",
]
