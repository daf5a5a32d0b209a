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
from scenegen.dataset.lazy import lazy_exports

# name -> the submodule it comes from; loaded on first use (scenegen.dataset.lazy)
__getattr__, __all__ = lazy_exports(__name__, {
    "dng": ("DngRaw", "decode_dng", "encode_dng", "read_dng", "write_dng"),
    "exr": ("decode_exr", "encode_exr", "pack_channels", "read_exr", "unpack_channels", "write_exr"),
    "flo": ("decode_flo", "encode_flo"),
    "json": ("decode_json", "encode_json", "read_json", "write_json"),
    "kitti": ("decode_kitti_disparity", "disparity_from_kitti_array", "encode_kitti_disparity", "kitti_disparity_array"),
    "kitti_flow": ("decode_kitti_flow_png", "encode_kitti_flow_png"),
    "npy": ("decode_npy", "decode_npz", "encode_npy", "encode_npz", "read_npy", "read_npz", "write_npy"),
    "pfm": ("decode_pfm", "encode_pfm", "read_pfm", "write_pfm"),
    "png": ("decode_png", "encode_png", "read_png", "write_png"),
    "sintel": ("decode_cam", "decode_dpt", "encode_cam", "encode_dpt"),
    "tracks": ("TRACK_KEYS", "TrackSet", "decode_tracks", "encode_tracks", "read_tracks", "write_tracks"),
})
