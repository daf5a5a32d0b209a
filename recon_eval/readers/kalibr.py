"""Kalibr camera-IMU results (``camchain-imucam.yaml``, Kalibr wiki "YAML formats"): per camera
``camN:`` a ``T_cam_imu`` (4x4, cam-from-IMU, row-major nested lists) and ``timeshift_cam_imu``
(seconds, ``t_imu = t_cam + shift``). Other keys (intrinsics, rostopic, ...) are read by nobody
here and ignored. Read through :mod:`scenegen.located_yaml`: duplicate keys refused, every error
names file:line: field.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from scenegen.errors import SpecError
from scenegen.located_yaml import Document
from scenegen.located_yaml.source import read_source
from scenegen.geometry.rotation import is_rotation


@dataclass(frozen=True)
class KalibrCamImu:
    """One camera's camera-IMU calibration: ``cam_from_imu`` (4, 4), ``timeshift_cam_imu_s``."""

    name: str
    cam_from_imu: np.ndarray
    timeshift_cam_imu_s: float


def read_kalibr_camchain(path) -> tuple[KalibrCamImu, ...]:
    """The cameras of a Kalibr camchain (``cam0``, ``cam1``, ... in order); each must hold
    T_cam_imu (a rigid 4x4) and timeshift_cam_imu (0 when absent, as Kalibr's camchain without
    a time calibration)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a Kalibr camchain-imucam.yaml)")
    try:
        root = Document(read_source(p, "Kalibr camchain"), str(p), p.parent).root.as_mapping("Kalibr camchain")
        out = []
        for key in root.keys():
            if not (key.startswith("cam") and key[3:].isdigit()):
                raise root.key_node(key).error("expected camN: blocks (cam0, cam1, ...)")
            cam = root.req(key).as_mapping(f"{key}: a camera block")
            rows = cam.req("T_cam_imu").items("a 4x4 matrix (4 rows)")
            if len(rows) != 4:
                raise cam.req("T_cam_imu").error(f"expected 4 rows of 4 numbers, got {len(rows)} rows")
            T = np.array([r.as_floats(4) for r in rows], dtype=np.float64)
            if not (is_rotation(T[:3, :3], 1e-6) and np.allclose(T[3], [0, 0, 0, 1])):
                raise cam.req("T_cam_imu").error("expected a rigid transform (rotation, translation, 0 0 0 1)")
            shift = cam.float("timeshift_cam_imu", 0.0, "s") if "timeshift_cam_imu" in cam else 0.0
            out.append(KalibrCamImu(key, T, float(shift)))
    except SpecError as exc:
        raise InputError(str(exc)) from None
    if not out:
        raise InputError(f"{p}: no camN: block with T_cam_imu")
    return tuple(sorted(out, key=lambda c: int(c.name[3:])))
