"""What a view's raw output holds: the mosaic file(s) and their record in ``cameras.json``.

A view of a camera with ``imaging.raw`` has ``views.<view>.raw`` in cameras.json::

    {"files": {"dng": "raw/<view>.dng", "png": "images/<view>_raw.png"},   # those written
     "cfa_pattern": "RGGB",              # top-left 2x2 block row by row (array [v, u])
     "black_level_dn": 64, "white_level_dn": 4095, "adc_bits": 12,
     "black_level_clipped": false,       # true only where the sensor clips at black
     "as_shot_neutral": [R, G, B],       # camera RGB of a neutral surface (1 / gains)
     "color_matrix_xyz_to_camera": 3x3,  # DNG ColorMatrix1, illuminant D65
     "isp": [{"stage": "demosaic", ...}, ...]}  # raw -> images/<view>.png, in order

The DNG holds the mosaic, CFA, levels, neutral and matrix itself (:mod:`.codecs.dng`); the PNG
holds only the mosaic (uint16, the DN as recorded). docs/dataset_format.md, docs/image_formation.md.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from scenegen.dataset.codecs.dng import DngRaw

RECORD_KEYS = ("files", "cfa_pattern", "black_level_dn", "white_level_dn", "adc_bits",
               "black_level_clipped", "as_shot_neutral", "color_matrix_xyz_to_camera", "isp")
FILE_KINDS = ("dng", "png")


@dataclass(frozen=True, eq=False)
class RawImage:
    """A view's raw mosaic with what is needed to interpret and develop it."""

    mosaic: np.ndarray  # (H, W) uint16 DN, array [v, u]
    cfa_pattern: str  # e.g. 'RGGB': the top-left 2x2 block row by row
    black_level_dn: float  # DN of zero signal (noise below it is kept unless clipped)
    white_level_dn: int  # largest recordable DN
    black_level_clipped: bool  # the sensor clipped its output at the black level
    as_shot_neutral: tuple[float, float, float]  # camera R, G, B of a neutral surface
    color_matrix: np.ndarray  # (3, 3) XYZ (D65) -> camera RGB
    isp: tuple[Mapping[str, Any], ...]  # recorded ISP stages: raw -> the delivered image
    path: str  # the file the mosaic was read from (relative to the dataset)


def raw_record(*, files: Mapping[str, str], cfa_pattern: str, black_level_dn: float,
               white_level_dn: int, adc_bits: int, black_level_clipped: bool, as_shot_neutral,
               color_matrix, isp) -> dict[str, Any]:
    """The ``views.<view>.raw`` entry of cameras.json (JSON-able)."""
    unknown = set(files) - set(FILE_KINDS)
    if not files or unknown:
        raise ValueError(f"raw files: one or more of {FILE_KINDS}, got {sorted(files)}")
    return {"files": dict(files), "cfa_pattern": str(cfa_pattern),
            "black_level_dn": black_level_dn, "white_level_dn": int(white_level_dn),
            "adc_bits": int(adc_bits), "black_level_clipped": bool(black_level_clipped),
            "as_shot_neutral": [float(v) for v in as_shot_neutral],
            "color_matrix_xyz_to_camera": np.asarray(color_matrix, dtype=np.float64).tolist(),
            "isp": [dict(s) for s in isp]}


def dng_of(mosaic: np.ndarray, record: Mapping[str, Any], camera_model: str) -> DngRaw:
    """The DNG content of a mosaic and its record."""
    return DngRaw(mosaic=mosaic, cfa_pattern=record["cfa_pattern"],
                  black_level_dn=record["black_level_dn"], white_level_dn=record["white_level_dn"],
                  as_shot_neutral=tuple(record["as_shot_neutral"]),
                  color_matrix=np.asarray(record["color_matrix_xyz_to_camera"]),
                  camera_model=camera_model)


def raw_image(mosaic: np.ndarray, record: Mapping[str, Any], path: str,
              dng: DngRaw | None = None) -> RawImage:
    """A :class:`RawImage` of a mosaic read from ``path``: levels, CFA and colour from the DNG
    when read from one, else from the record; clipping and ISP from the record."""
    src = dng  # None: the levels, CFA and colour data come from the record
    return RawImage(
        mosaic=mosaic,
        cfa_pattern=src.cfa_pattern if src else str(record["cfa_pattern"]),
        black_level_dn=src.black_level_dn if src else float(record["black_level_dn"]),
        white_level_dn=src.white_level_dn if src else int(record["white_level_dn"]),
        black_level_clipped=bool(record["black_level_clipped"]),
        as_shot_neutral=src.as_shot_neutral if src else tuple(record["as_shot_neutral"]),
        color_matrix=src.color_matrix if src else np.asarray(record["color_matrix_xyz_to_camera"]),
        isp=tuple(record["isp"]), path=path)
