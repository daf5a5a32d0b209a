"""Dr.Jit's array operations for the camera arithmetic (:mod:`scenegen.geometry.camera.arith`),
so the renderer's rays run the same lines as the numpy camera."""
from __future__ import annotations

import math

import drjit as dr

from scenegen.geometry.camera.arith import ArrayOps

DRJIT_OPS = ArrayOps(dr.sqrt, dr.atan2, dr.sin, dr.cos, dr.select, lambda x: dr.full(type(x), math.nan, dr.width(x)))
