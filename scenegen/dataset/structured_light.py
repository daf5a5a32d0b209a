"""Structured-light truth as stored (docs/dataset_format.md, "Structured light").

* ``truth/<view>_projector.npz``: one member per :class:`ProjectorTruthKind` (``<kind>.npy``):
  ``projector_uv`` (H, W, 2) float64, the projector pixel (OpenCV centres) the view's stored
  ``points_world`` (float32, taken exactly) projects to through the projector's model, NaN where
  the pixel has no point or the projection is invalid (behind the projector, beyond its fold);
  ``projector_lit`` (H, W) bool: the projector lights the point (its pixel inside the projector
  image, the side of the surface the camera sees facing the projector, nothing between them);
  ``projector_column`` / ``projector_row`` (H, W) int32: the projector pixel ``floor(u + 0.5)``,
  ``floor(v + 0.5)`` a perfect decoder reads, and ``gray_column`` / ``gray_row`` their Gray codes
  ``c ^ (c >> 1)``; -1 where not lit; ``clear_column`` / ``clear_row`` (H, W) bool: lit, and
  the rays through the pixel's four corners meet lit points in the same projector column (row):
  the pixel's footprint lies in one column, so its code is unambiguous (a pixel straddling a
  column edge, a shadow edge or a depth edge mixes codes and a decoder may read either).
* ``patterns/<view>/sequence.json``: ``{"format": "scenegen.patterns/1", "view", "projector":
  {name, camera (Camera.to_dict), projector_from_world 4x4, cam_from_projector 4x4, radiometry},
  "patterns": [{index, name, axis, bit, inverse, image, linear}]}``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset.codecs.npy import decode_npz, encode_npz
from scenegen.dataset.truth_kinds import PROJECTOR_TRUTH_INFO, ProjectorTruthKind

PATTERNS_FORMAT = "scenegen.patterns/1"
K = ProjectorTruthKind


@dataclass(frozen=True)
class ProjectorTruth:
    """A projector-lit view's per-pixel truth (module docstring); arrays (H, W[, 2])."""

    uv: np.ndarray
    lit: np.ndarray
    column: np.ndarray
    row: np.ndarray
    gray_column: np.ndarray
    gray_row: np.ndarray
    clear_column: np.ndarray
    clear_row: np.ndarray

    def arrays(self) -> dict[ProjectorTruthKind, np.ndarray]:
        return {K.PROJECTOR_UV: self.uv, K.PROJECTOR_LIT: self.lit, K.PROJECTOR_COLUMN: self.column,
                K.PROJECTOR_ROW: self.row, K.GRAY_COLUMN: self.gray_column, K.GRAY_ROW: self.gray_row,
                K.CLEAR_COLUMN: self.clear_column, K.CLEAR_ROW: self.clear_row}


def encode_projector_truth(t: ProjectorTruth) -> bytes:
    """NPZ bytes of the truth, each array in its kind's dtype (ValueError on a wrong shape)."""
    hw = t.lit.shape
    out = {}
    for kind, a in t.arrays().items():
        info = PROJECTOR_TRUTH_INFO[kind]
        want = hw + ((len(info.components),) if info.components else ())
        if a.shape != want:
            raise ValueError(f"{kind}: expected shape {want}, got {a.shape}")
        out[str(kind)] = np.ascontiguousarray(a, dtype=info.dtype)
    return encode_npz(out)


def decode_projector_truth(data: bytes) -> ProjectorTruth:
    """The truth of NPZ bytes (ValueError naming a missing member or a wrong dtype/shape)."""
    arrays = decode_npz(data, required=tuple(str(k) for k in K))
    hw = arrays[str(K.PROJECTOR_LIT)].shape
    for kind in K:
        a, info = arrays[str(kind)], PROJECTOR_TRUTH_INFO[kind]
        want = hw + ((len(info.components),) if info.components else ())
        if a.dtype != np.dtype(info.dtype) or a.shape != want:
            raise ValueError(f"member {kind}.npy: expected {np.dtype(info.dtype)} {want}, got {a.dtype} {a.shape}")
    g = lambda k: arrays[str(k)]
    return ProjectorTruth(g(K.PROJECTOR_UV), g(K.PROJECTOR_LIT), g(K.PROJECTOR_COLUMN), g(K.PROJECTOR_ROW),
                          g(K.GRAY_COLUMN), g(K.GRAY_ROW), g(K.CLEAR_COLUMN), g(K.CLEAR_ROW))


def decode_pattern_sequence(doc, source: str) -> dict:
    """A parsed ``sequence.json`` checked for its format and pattern list (ValueError naming ``source``)."""
    if not isinstance(doc, dict) or doc.get("format") != PATTERNS_FORMAT or not isinstance(doc.get("patterns"), list) \
            or not isinstance(doc.get("projector"), dict):
        raise ValueError(f"{source}: expected a {PATTERNS_FORMAT} document with 'projector' and 'patterns'")
    return doc
