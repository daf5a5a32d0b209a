"""Dr.Jit's array operations for the camera arithmetic (:mod:`scenegen.geometry.camera.arith`),
so the renderer's rays run the same lines as the numpy camera."""
from __future__ import annotations

import math

import drjit as dr


class DrJitOps:
    """sqrt, atan2, sin, cos, select and nan_like on Dr.Jit arrays."""

    sqrt = staticmethod(dr.sqrt)
    atan2 = staticmethod(dr.atan2)
    sin = staticmethod(dr.sin)
    cos = staticmethod(dr.cos)
    select = staticmethod(dr.select)

    @staticmethod
    def nan_like(x):
        return dr.full(type(x), math.nan, dr.width(x))


DRJIT_OPS = DrJitOps()
