"""Per-pixel truth of a view as stored: the kinds, their channels, the rules, encode and decode.

Kinds (:class:`TruthKind`, the keys of a truth dict, :data:`TRUTH_KEYS`; each kind's storage in
:data:`TRUTH_KIND_INFO`), all over the view's pixel centres, (H, W) or (H, W, C):

* ``depth_z`` (H, W) metres along the optical axis; ``range`` (H, W) metres from the optical
  centre (+inf where the ray hit nothing);
* ``points_world`` / ``points_cam`` (H, W, 3) metres, world / OpenCV camera frame;
* ``normals_world`` / ``normals_cam`` (H, W, 3) unit shading normals (not flipped to the viewer);
* ``uv`` (H, W, 2) texture coordinates (v = 0 at the texture's top row);
* ``object_id`` / ``instance_id`` (H, W) uint32, 0 = no object; ``valid`` (H, W) bool.

Misses (``~valid``) carry depth_z = range = +inf, NaN points, normals and uv, and ids 0.
Files: ``truth/<view>.exr`` (float32 channels of :data:`TRUTH_FLOAT_CHANNELS`),
``truth/<view>_ids.exr`` (uint32), ``truth/<view>_valid.png`` (uint8, 255 = valid).
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from scenegen.dataset.codecs.exr import DEFAULT_EXR_COMPRESSION, encode_exr, pack_channels, unpack_channels
from scenegen.dataset.codecs.png import encode_png
from scenegen.dataset.truth_kinds import (TRUTH_DISTANCE_KEYS, TRUTH_FLOAT_CHANNELS, TRUTH_ID_KEYS, TRUTH_KEYS,  # noqa: F401
                                          TRUTH_KIND_INFO, TruthKind, TruthKindInfo)


_UINT32_MAX = np.iinfo(np.uint32).max
VALID_PNG_VALUE = 255  # a valid pixel in truth/<view>_valid.png
#: The linear image's channels (images/<view>_linear.exr).
LINEAR_CHANNELS = ("R", "G", "B")


def check_truth(truth: Mapping[str, np.ndarray], shape: tuple[int, int] | None = None) -> dict:
    """Validate a truth dict (keys :data:`TRUTH_KEYS`) and return it with arrays as stored.

    Float keys may be any float dtype; they are stored, and returned, as float32 (float64 input,
    e.g. from the truth pass, is rounded to nearest: about 6e-8 relative, far below 1e-3 px of
    reprojection error). ``object_id``/``instance_id``: integers in [0, 2^32) (returned as
    uint32); ``valid``: bool. Shapes: (H, W), (H, W, 3) for points and normals, (H, W, 2) for uv; ``shape`` (H, W)
    if given. Misses (``~valid``) must carry depth_z = range = +inf, NaN points, normals and uv,
    and ids 0; hits finite depth_z, range, points and normals.
    """
    missing = [k.value for k in TRUTH_KEYS if k not in truth]
    extra = [k for k in truth if k not in TRUTH_KEYS]
    if missing or extra:
        raise ValueError(f"truth keys: missing {missing}, unknown {extra}; expected {[k.value for k in TRUTH_KEYS]}")
    valid = np.asarray(truth[TruthKind.VALID])
    if valid.dtype != np.bool_ or valid.ndim != 2:
        raise TypeError(f"truth 'valid' must be an (H, W) bool array, got {valid.dtype} {valid.shape}")
    hw = valid.shape
    if shape is not None and tuple(shape) != hw:
        raise ValueError(f"truth is {hw} (H, W) but the image is {tuple(shape)}")
    out: dict[str, np.ndarray] = {TruthKind.VALID: valid}
    miss = ~valid
    n_valid = int(np.count_nonzero(valid))
    n_miss = valid.size - n_valid
    # whole-array tests and counts: no copies through the masks (this runs on every frame)
    for key, (_, comps) in TRUTH_FLOAT_CHANNELS.items():
        a = np.asarray(truth[key])
        name = key.value
        want = hw if comps is None else hw + (len(comps),)
        if not np.issubdtype(a.dtype, np.floating):
            raise TypeError(f"truth {name!r} must be a float array (stored as float32), got {a.dtype}")
        if a.shape != want:
            raise ValueError(f"truth {name!r} must have shape {want}, got {a.shape}")
        a = a.astype(np.float32, copy=False)
        n_comp = 1 if comps is None else len(comps)
        if key in TRUTH_DISTANCE_KEYS:
            if np.count_nonzero((a == np.inf) & miss) != n_miss:
                raise ValueError(f"truth {name!r} must be +inf where valid is False")
        else:
            planes = [a] if comps is None else [a[..., i] for i in range(n_comp)]  # contiguous when planar
            if any(np.count_nonzero(np.isnan(p) & miss) != n_miss for p in planes):
                raise ValueError(f"truth {name!r} must be NaN where valid is False")
        # misses are +inf or NaN, never finite: all hits are finite iff the finite count is theirs
        if key != TruthKind.UV and np.count_nonzero(np.isfinite(a)) != n_valid * n_comp:
            raise ValueError(f"truth {name!r} must be finite where valid is True")
        out[key] = a
    for key in TRUTH_ID_KEYS:
        a = np.asarray(truth[key])
        name = key.value
        if not np.issubdtype(a.dtype, np.integer) or a.shape != hw:
            raise TypeError(f"truth {name!r} must be an integer (H, W) = {hw} array, got {a.dtype} {a.shape}")
        if a.dtype != np.uint32 and a.size and (a.min() < 0 or a.max() > _UINT32_MAX):
            raise ValueError(f"truth {name!r} values must lie in [0, 2^32 - 1]")
        a = a.astype(np.uint32, copy=False)
        if np.count_nonzero((a != 0) & miss):
            raise ValueError(f"truth {name!r} must be 0 where valid is False")
        out[key] = a
    return out


def truth_float_channels(truth: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The float EXR channels of a checked truth dict."""
    ch: dict[str, np.ndarray] = {}
    for key, (prefix, comps) in TRUTH_FLOAT_CHANNELS.items():
        if comps is None:
            ch[prefix] = truth[key]
        else:
            ch.update(pack_channels(prefix, truth[key], comps))
    return ch


def truth_id_channels(truth: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The uint32 EXR channels (truth/<view>_ids.exr) of a checked truth dict, named by kind."""
    return {k.value: truth[k] for k in TRUTH_ID_KEYS}


def encode_truth(truth: Mapping[str, np.ndarray], shape: tuple[int, int] | None = None,
                 exr_compression: str = DEFAULT_EXR_COMPRESSION) -> dict[str, bytes]:
    """The three truth files of a view, by key ``truth``, ``ids``, ``valid`` (see the module
    docstring); ``truth`` is checked with :func:`check_truth` first. ``exr_compression``: of
    :data:`scenegen.dataset.codecs.exr.EXR_COMPRESSIONS` (the spec's ``render.exr_compression``)."""
    t = check_truth(truth, shape=shape)
    return {
        "truth": encode_exr(truth_float_channels(t), exr_compression),
        "ids": encode_exr(truth_id_channels(t), exr_compression),
        "valid": encode_png(np.where(t[TruthKind.VALID], np.uint8(VALID_PNG_VALUE), np.uint8(0))),
    }


def decode_truth(float_channels: Mapping[str, np.ndarray], id_channels: Mapping[str, np.ndarray],
                 valid_png: np.ndarray) -> dict[str, np.ndarray]:
    """The truth dict of a view from its decoded files (inverse of :func:`encode_truth`)."""
    out: dict[str, np.ndarray] = {}
    for key, (prefix, comps) in TRUTH_FLOAT_CHANNELS.items():
        out[key] = float_channels[prefix] if comps is None else unpack_channels(float_channels, prefix, comps)
    for key in TRUTH_ID_KEYS:
        out[key] = id_channels[key.value]
    out[TruthKind.VALID] = np.asarray(valid_png) == VALID_PNG_VALUE
    return out
