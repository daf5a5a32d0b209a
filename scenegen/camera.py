"""Camera models: projection, unprojection, validity. numpy only at import.

Models and their parameter order (OpenCV's and COLMAP's):

* ``pinhole``: fx, fy, cx, cy, skew.
  ``u = fx x + skew y + cx``, ``v = fy y + cy`` with ``(x, y) = (X / Z, Y / Z)``.
* ``opencv``: pinhole + Brown-Conrady with OpenCV's rational and thin-prism terms, coefficients in
  OpenCV's order ``k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4`` (``cv2.projectPoints``;
  OpenCV's tilt terms tau_x, tau_y are not supported). With ``r2 = x^2 + y^2``::

      radial = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
      xd = x radial + 2 p1 x y + p2 (r2 + 2 x^2) + s1 r2 + s2 r2^2
      yd = y radial + p1 (r2 + 2 y^2) + 2 p2 x y + s3 r2 + s4 r2^2
      u = fx xd + skew yd + cx,  v = fy yd + cy

* ``fisheye``: OpenCV fisheye = Kannala-Brandt with ``k1, k2, k3, k4``
  (``cv2.fisheye.projectPoints``; COLMAP ``OPENCV_FISHEYE``). With ``theta`` the angle between the
  ray and the optical axis, ``theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 +
  k4 theta^8)``, ``(xd, yd) = theta_d (X, Y) / |(X, Y)|``, then the pinhole with skew
  (``skew = fx * alpha`` in OpenCV's fisheye terms). ``theta = atan2(|(X, Y)|, Z)``, so rays
  beyond 90 degrees are projected too.

Pixels follow OpenCV (centre of the top-left pixel = (0, 0)), see :mod:`scenegen.conventions`.

One implementation of the arithmetic serves numpy (float64, the evaluator) and Dr.Jit (float32,
the renderer's rays): the ``*_xy`` functions below use only + - * /, sqrt, atan2, sin, cos and a
select, on whatever array type they are given, with parameters passed as plain attributes (Python
floats here, opaque Dr.Jit floats in the Mitsuba sensor).

Undistortion is Newton's method with the analytic Jacobian, started at the distorted point, with
a fixed iteration count per camera: at construction the camera measures, over its whole pixel
border and an interior grid, how many iterations the worst pixel needs to reach
``UNDISTORT_TOL_PX`` of reprojection residual in float64, and adds one. A fixed count keeps the
Dr.Jit kernel branch-free; the measured count is ``Camera.undistort_iterations``.

Validity: a distortion whose mapping folds over (Jacobian determinant <= 0) at a pixel inside the
image is rejected with ``ValueError`` naming that pixel. Points beyond the fold radius (the
monotonic region) project to NaN and are flagged invalid, as do points behind a non-fisheye
camera, and NaN inputs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

MODELS = ("pinhole", "opencv", "fisheye")
OPENCV_COEFFS = ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4")
FISHEYE_COEFFS = ("k1", "k2", "k3", "k4")
#: Reprojection residual (px, float64) that sets each camera's undistortion iteration count.
UNDISTORT_TOL_PX = 1e-10
#: Newton iterations beyond which undistortion is declared non-convergent.
MAX_UNDISTORT_ITERATIONS = 60
#: Largest angle from the optical axis searched for a non-fisheye model (degrees).
_MAX_PERSPECTIVE_ANGLE_DEG = 89.9


# --- array back ends: numpy or Dr.Jit, chosen by the type of the input ---------------------------
class _NumpyOps:
    sqrt = staticmethod(np.sqrt)
    atan2 = staticmethod(np.arctan2)
    sin = staticmethod(np.sin)
    cos = staticmethod(np.cos)
    select = staticmethod(np.where)

    @staticmethod
    def nan_like(x):
        return np.full(np.shape(x), np.nan)


class _DrJitOps:
    def __init__(self):
        import drjit as dr

        self.dr = dr
        self.sqrt, self.atan2, self.sin, self.cos, self.select = dr.sqrt, dr.atan2, dr.sin, dr.cos, dr.select

    def nan_like(self, x):
        return self.dr.full(type(x), math.nan, self.dr.width(x))


_NUMPY = _NumpyOps()
_DRJIT = None


def ops_for(x):
    """The arithmetic back end for an array: Dr.Jit for Dr.Jit arrays, numpy otherwise."""
    global _DRJIT
    if type(x).__module__.startswith("drjit"):
        if _DRJIT is None:
            _DRJIT = _DrJitOps()
        return _DRJIT
    return _NUMPY


# --- model arithmetic on components (numpy or Dr.Jit) ------------------------------------------
def distort_opencv_xy(x, y, p):
    """OpenCV distortion of normalised coordinates (x, y) -> (xd, yd); p has k1..k6, p1, p2, s1..s4."""
    r2 = x * x + y * y
    num = 1.0 + r2 * (p.k1 + r2 * (p.k2 + r2 * p.k3))
    den = 1.0 + r2 * (p.k4 + r2 * (p.k5 + r2 * p.k6))
    radial = num / den
    xd = x * radial + 2.0 * p.p1 * x * y + p.p2 * (r2 + 2.0 * x * x) + r2 * (p.s1 + r2 * p.s2)
    yd = y * radial + p.p1 * (r2 + 2.0 * y * y) + 2.0 * p.p2 * x * y + r2 * (p.s3 + r2 * p.s4)
    return xd, yd


def distort_opencv_jacobian_xy(x, y, p):
    """(xd, yd, dxd/dx, dxd/dy, dyd/dx, dyd/dy) of :func:`distort_opencv_xy`."""
    r2 = x * x + y * y
    num = 1.0 + r2 * (p.k1 + r2 * (p.k2 + r2 * p.k3))
    den = 1.0 + r2 * (p.k4 + r2 * (p.k5 + r2 * p.k6))
    dnum = p.k1 + r2 * (2.0 * p.k2 + 3.0 * r2 * p.k3)
    dden = p.k4 + r2 * (2.0 * p.k5 + 3.0 * r2 * p.k6)
    radial = num / den
    dradial = (dnum * den - num * dden) / (den * den)  # d radial / d r2
    prism_x = p.s1 + 2.0 * r2 * p.s2  # d (s1 r2 + s2 r2^2) / d r2
    prism_y = p.s3 + 2.0 * r2 * p.s4
    xd = x * radial + 2.0 * p.p1 * x * y + p.p2 * (r2 + 2.0 * x * x) + r2 * (p.s1 + r2 * p.s2)
    yd = y * radial + p.p1 * (r2 + 2.0 * y * y) + 2.0 * p.p2 * x * y + r2 * (p.s3 + r2 * p.s4)
    j11 = radial + 2.0 * x * x * dradial + 2.0 * p.p1 * y + 6.0 * p.p2 * x + 2.0 * x * prism_x
    j12 = 2.0 * x * y * dradial + 2.0 * p.p1 * x + 2.0 * p.p2 * y + 2.0 * y * prism_x
    j21 = 2.0 * x * y * dradial + 2.0 * p.p1 * x + 2.0 * p.p2 * y + 2.0 * x * prism_y
    j22 = radial + 2.0 * y * y * dradial + 6.0 * p.p1 * y + 2.0 * p.p2 * x + 2.0 * y * prism_y
    return xd, yd, j11, j12, j21, j22


def newton_step_opencv_xy(x, y, xd, yd, p):
    """One Newton step of solving distort_opencv_xy(x, y) = (xd, yd) for (x, y)."""
    fx_, fy_, j11, j12, j21, j22 = distort_opencv_jacobian_xy(x, y, p)
    ex, ey = xd - fx_, yd - fy_
    inv_det = 1.0 / (j11 * j22 - j12 * j21)
    return x + (j22 * ex - j12 * ey) * inv_det, y + (j11 * ey - j21 * ex) * inv_det


def undistort_opencv_xy(xd, yd, p, iterations: int):
    """Inverse of :func:`distort_opencv_xy` by ``iterations`` Newton steps from (xd, yd)."""
    x, y = xd, yd
    for _ in range(iterations):
        x, y = newton_step_opencv_xy(x, y, xd, yd, p)
    return x, y


def fisheye_theta_d(theta, p):
    """Kannala-Brandt theta_d(theta) = theta (1 + k1 t^2 + k2 t^4 + k3 t^6 + k4 t^8)."""
    t2 = theta * theta
    return theta * (1.0 + t2 * (p.k1 + t2 * (p.k2 + t2 * (p.k3 + t2 * p.k4))))


def fisheye_dtheta_d(theta, p):
    t2 = theta * theta
    return 1.0 + t2 * (3.0 * p.k1 + t2 * (5.0 * p.k2 + t2 * (7.0 * p.k3 + t2 * 9.0 * p.k4)))


def fisheye_theta_from_theta_d(theta_d, p, iterations: int):
    """Inverse of :func:`fisheye_theta_d` by Newton from theta = theta_d."""
    theta = theta_d
    for _ in range(iterations):
        theta = theta - (fisheye_theta_d(theta, p) - theta_d) / fisheye_dtheta_d(theta, p)
    return theta


def project_xyz(X, Y, Z, p, model: str):
    """Camera-frame points -> pixels (u, v) and a validity mask, on numpy or Dr.Jit arrays.

    ``p`` carries fx, fy, cx, cy, skew, the model's coefficients and ``limit`` (the largest valid
    r^2 = x^2 + y^2 for opencv, the largest valid theta for fisheye, in radians). Invalid
    points give NaN pixels.
    """
    ops = ops_for(X)
    if model == "fisheye":
        rho = ops.sqrt(X * X + Y * Y)
        theta = ops.atan2(rho, Z)
        theta_d = fisheye_theta_d(theta, p)
        small = rho < 1e-12 * ops.sqrt(X * X + Y * Y + Z * Z)
        safe_rho = ops.select(small, 1.0, rho)
        scale = ops.select(small, 1.0 / Z, theta_d / safe_rho)  # theta_d / rho -> 1 / Z on axis
        xd, yd = X * scale, Y * scale
        valid = (theta <= p.limit) & ((~small) | (Z > 0))
    else:
        valid = Z > 0
        safe_z = ops.select(valid, Z, 1.0)
        x, y = X / safe_z, Y / safe_z
        if model == "opencv":
            valid = valid & (x * x + y * y <= p.limit)
            xd, yd = distort_opencv_xy(x, y, p)
        else:
            xd, yd = x, y
    u = p.fx * xd + p.skew * yd + p.cx
    v = p.fy * yd + p.cy
    valid = valid & (u == u) & (v == v)  # NaN input -> invalid
    nan = ops.nan_like(u)
    return ops.select(valid, u, nan), ops.select(valid, v, nan), valid


def unproject_uv(u, v, p, model: str, iterations: int):
    """Pixels -> unit ray directions (dx, dy, dz) in the camera frame, on numpy or Dr.Jit arrays."""
    ops = ops_for(u)
    yd = (v - p.cy) / p.fy
    xd = (u - p.cx - p.skew * yd) / p.fx
    if model == "fisheye":
        theta_d = ops.sqrt(xd * xd + yd * yd)
        theta = fisheye_theta_from_theta_d(theta_d, p, iterations)
        small = theta_d < 1e-12
        s = ops.select(small, 1.0, ops.sin(theta) / ops.select(small, 1.0, theta_d))
        return xd * s, yd * s, ops.cos(theta)
    if model == "opencv":
        xd, yd = undistort_opencv_xy(xd, yd, p, iterations)
    inv_norm = 1.0 / ops.sqrt(xd * xd + yd * yd + 1.0)
    return xd * inv_norm, yd * inv_norm, inv_norm


# --- the user-facing camera ---------------------------------------------------------------------
def _pixel_grid_border_and_interior(width: int, height: int, step: int) -> np.ndarray:
    """(N, 2) pixel positions: every pixel of the extreme border [-0.5, W-0.5] x [-0.5, H-0.5]
    plus an interior grid with ``step`` px spacing."""
    us = np.arange(width, dtype=np.float64)
    vs = np.arange(height, dtype=np.float64)
    x0, x1, y0, y1 = -0.5, width - 0.5, -0.5, height - 0.5
    border = np.concatenate([
        np.stack([us, np.full_like(us, y0)], 1), np.stack([us, np.full_like(us, y1)], 1),
        np.stack([np.full_like(vs, x0), vs], 1), np.stack([np.full_like(vs, x1), vs], 1),
        np.array([[x0, y0], [x1, y0], [x0, y1], [x1, y1]]),
    ])
    gu, gv = np.meshgrid(np.arange(0, width, step, dtype=float), np.arange(0, height, step, dtype=float))
    return np.concatenate([border, np.stack([gu.ravel(), gv.ravel()], 1)])


@dataclass(frozen=True)
class Camera:
    """A calibrated camera: model, image size (px) and intrinsics (px), OpenCV conventions.

    ``dist`` is the model's coefficient vector: 12 values for ``opencv`` in OpenCV's order
    (shorter OpenCV vectors of length 4, 5 or 8 are zero-padded), 4 for ``fisheye``, empty for
    ``pinhole``. Build from OpenCV data with :meth:`from_opencv` / :meth:`from_opencv_fisheye`.
    """

    model: str
    width: int  # px
    height: int  # px
    fx: float  # px
    fy: float  # px
    cx: float  # px, OpenCV pixel-centre convention
    cy: float  # px
    skew: float = 0.0  # px; K[0, 1]
    dist: tuple = ()
    # derived at construction (not part of equality)
    undistort_iterations: int = field(default=0, init=False, compare=False)
    limit: float = field(default=math.inf, init=False, compare=False, repr=False)

    def __post_init__(self):
        if self.model not in MODELS:
            raise ValueError(f"camera model must be one of {MODELS}, got {self.model!r}")
        for name in ("width", "height"):
            val = getattr(self, name)
            if isinstance(val, bool) or int(val) != val or val <= 0:
                raise ValueError(f"{name} must be a positive integer (px), got {val!r}")
            object.__setattr__(self, name, int(val))
        for name in ("fx", "fy", "cx", "cy", "skew"):
            val = float(getattr(self, name))
            if not math.isfinite(val):
                raise ValueError(f"{name} must be finite, got {val!r}")
            object.__setattr__(self, name, val)
        if self.fx <= 0 or self.fy <= 0:
            raise ValueError(f"focal lengths must be positive (px), got fx={self.fx}, fy={self.fy}")
        object.__setattr__(self, "dist", self._normalised_dist(self.model, self.dist))
        limit, iterations = self._validate_and_measure()
        object.__setattr__(self, "limit", limit)
        object.__setattr__(self, "undistort_iterations", iterations)

    # ----- construction
    @staticmethod
    def _normalised_dist(model: str, dist) -> tuple:
        d = tuple(float(c) for c in (() if dist is None else np.asarray(dist, float).ravel()))
        if not all(math.isfinite(c) for c in d):
            raise ValueError(f"distortion coefficients must be finite, got {d}")
        if model == "pinhole":
            if any(d):
                raise ValueError("a pinhole camera has no distortion coefficients")
            return ()
        if model == "fisheye":
            if len(d) != 4:
                raise ValueError(f"fisheye distortion needs 4 coefficients k1..k4, got {len(d)}")
            return d
        if len(d) == 14:
            if d[12] or d[13]:
                raise ValueError("OpenCV tilt coefficients (tau_x, tau_y) are not supported")
            d = d[:12]
        if len(d) not in (4, 5, 8, 12):
            raise ValueError(
                "opencv distortion needs 4, 5, 8, 12 (or 14 with zero tilt) coefficients in OpenCV's"
                f" order k1, k2, p1, p2[, k3[, k4, k5, k6[, s1, s2, s3, s4]]], got {len(d)}")
        return d + (0.0,) * (12 - len(d))

    @classmethod
    def from_opencv(cls, K, dist, size) -> "Camera":
        """From an OpenCV camera matrix K (3x3, skew in K[0, 1]), distortion vector and (W, H)."""
        K = np.asarray(K, dtype=np.float64)
        if K.shape != (3, 3) or K[1, 0] != 0 or K[2, 0] != 0 or K[2, 1] != 0 or K[2, 2] != 1:
            raise ValueError(f"K must be an upper-triangular 3x3 with K[2,2] = 1, got {K.tolist()}")
        d = () if dist is None else tuple(np.asarray(dist, float).ravel())
        model = "opencv" if any(d) else "pinhole"
        return cls(model, int(size[0]), int(size[1]), K[0, 0], K[1, 1], K[0, 2], K[1, 2], K[0, 1],
                   d if model == "opencv" else ())

    @classmethod
    def from_opencv_fisheye(cls, K, D, size, alpha: float = 0.0) -> "Camera":
        """From ``cv2.fisheye`` data: K, D = (k1, k2, k3, k4), (W, H) and skew ``alpha``."""
        K = np.asarray(K, dtype=np.float64)
        skew = K[0, 1] if alpha == 0.0 else alpha * K[0, 0]
        return cls("fisheye", int(size[0]), int(size[1]), K[0, 0], K[1, 1], K[0, 2], K[1, 2], skew,
                   tuple(np.asarray(D, float).ravel()))

    @classmethod
    def from_fov(cls, fov_x_deg: float, size, model: str = "pinhole", dist=()) -> "Camera":
        """Square pixels, principal point at the image centre ((W-1)/2, (H-1)/2), horizontal FoV
        in degrees (of the undistorted pinhole)."""
        if not 0 < fov_x_deg < 180:
            raise ValueError(f"fov_deg must be in (0, 180), got {fov_x_deg}")
        w, h = int(size[0]), int(size[1])
        f = (w / 2.0) / math.tan(math.radians(fov_x_deg) / 2.0)
        return cls(model, w, h, f, f, (w - 1) / 2.0, (h - 1) / 2.0, 0.0, dist)

    # ----- parameters
    @property
    def K(self) -> np.ndarray:
        """(3, 3) camera matrix, OpenCV pixel convention, skew in K[0, 1]."""
        return np.array([[self.fx, self.skew, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def size(self) -> tuple[int, int]:
        return self.width, self.height

    def coefficients(self) -> dict:
        names = {"opencv": OPENCV_COEFFS, "fisheye": FISHEYE_COEFFS}.get(self.model, ())
        return dict(zip(names, self.dist))

    def params(self) -> SimpleNamespace:
        """Plain-float parameters for the ``*_xy`` arithmetic (the Mitsuba sensor makes opaque
        Dr.Jit copies of these)."""
        p = dict(fx=self.fx, fy=self.fy, cx=self.cx, cy=self.cy, skew=self.skew, limit=self.limit)
        p.update({n: 0.0 for n in OPENCV_COEFFS})
        p.update(self.coefficients())
        return SimpleNamespace(**p)

    def to_opencv(self) -> tuple[np.ndarray, np.ndarray]:
        """(K, dist) for OpenCV: ``cv2.projectPoints`` (opencv/pinhole; note OpenCV ignores skew
        there) or ``cv2.fisheye`` (fisheye; pass ``alpha = skew / fx``). The dist vector is the
        shortest OpenCV length (5, 8 or 12) that keeps every non-zero coefficient."""
        if self.model == "fisheye":
            return self.K, np.array(self.dist)
        d = np.array(self.dist if self.dist else (0.0,) * 12)
        n = 12 if any(d[8:]) else 8 if any(d[5:8]) else 5
        return self.K, d[:n].copy()

    def with_size(self, width: int, height: int) -> "Camera":
        return Camera(self.model, width, height, self.fx, self.fy, self.cx, self.cy, self.skew, self.dist)

    def to_dict(self) -> dict:
        """JSON form (cameras.json): model parameters plus K and OpenCV's dist for other readers."""
        K, d = self.to_opencv()
        return {
            "model": self.model, "width": self.width, "height": self.height,
            "fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy, "skew": self.skew,
            "dist": list(self.dist), "coefficients": self.coefficients(),
            "K": K.tolist(), "opencv_dist": d.tolist(),
            "pixel_convention": "opencv: centre of the top-left pixel is (0, 0)",
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Camera":
        return cls(d["model"], d["width"], d["height"], d["fx"], d["fy"], d["cx"], d["cy"],
                   d.get("skew", 0.0), tuple(d.get("dist", ())))

    # ----- projection
    def project(self, points_cam, return_valid: bool = False):
        """Project camera-frame points (N, 3) metres -> pixels (N, 2), OpenCV convention.

        Points behind a non-fisheye camera, beyond the model's valid field of view, or with NaN
        coordinates give NaN pixels; ``return_valid=True`` also returns the (N,) bool mask.
        """
        P = np.asarray(points_cam, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != 3:
            raise ValueError(f"points_cam must be (N, 3), got shape {P.shape}")
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            u, v, valid = project_xyz(P[:, 0], P[:, 1], P[:, 2], self.params(), self.model)
        uv = np.stack([u, v], axis=1)
        return (uv, valid) if return_valid else uv

    def unproject_unit(self, pixels) -> np.ndarray:
        """Pixels (N, 2) -> unit ray directions (N, 3) in the camera frame (NaN for NaN input)."""
        uv = np.asarray(pixels, dtype=np.float64)
        if uv.ndim != 2 or uv.shape[1] != 2:
            raise ValueError(f"pixels must be (N, 2), got shape {uv.shape}")
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            d = unproject_uv(uv[:, 0], uv[:, 1], self.params(), self.model, self.undistort_iterations)
        return np.stack(d, axis=1)

    def unproject(self, pixels) -> np.ndarray:
        """Pixels (N, 2) -> points on the z = 1 plane (N, 3) in the camera frame.

        Rays at or beyond 90 degrees (fisheye) have no z = 1 point and give NaN; use
        :meth:`unproject_unit` for those.
        """
        d = self.unproject_unit(pixels)
        with np.errstate(invalid="ignore", divide="ignore"):
            z1 = d / d[:, 2:3]
        z1[~(d[:, 2] > 0)] = np.nan
        return z1

    # ----- validity and field of view
    def _validate_and_measure(self) -> tuple[float, int]:
        limit = self._fold_limit()
        if self.model == "pinhole":
            return limit, 0
        grid = _pixel_grid_border_and_interior(self.width, self.height, max(1, min(self.width, self.height) // 64))
        p = SimpleNamespace(**{**vars(self._raw_params()), "limit": limit})
        yd = (grid[:, 1] - p.cy) / p.fy
        xd = (grid[:, 0] - p.cx - p.skew * yd) / p.fx
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            if self.model == "opencv":
                def residual_px(xy):
                    ex, ey = distort_opencv_xy(xy[0], xy[1], p)
                    return np.hypot((ex - xd) * p.fx, (ey - yd) * p.fy)

                (x, y), done, worst = _newton_until_converged(
                    (xd, yd), residual_px, lambda xy: newton_step_opencv_xy(xy[0], xy[1], xd, yd, p))
                bad = ~done | (x * x + y * y > limit)
            else:
                theta_d = np.hypot(xd, yd)
                theta, done, worst = _newton_until_converged(
                    theta_d, lambda th: np.abs(fisheye_theta_d(th, p) - theta_d) * min(p.fx, p.fy),
                    lambda th: th - (fisheye_theta_d(th, p) - theta_d) / fisheye_dtheta_d(th, p))
                bad = ~done | (theta > limit)
        if bad.any():
            u, v = grid[np.argmax(bad)]
            raise ValueError(
                f"{self.model} camera: pixel ({u:.1f}, {v:.1f}) of the {self.width}x{self.height} image has no"
                " ray inside the distortion's valid (monotonic) region; the distortion folds over or the"
                " image extends beyond the model's field of view")
        return limit, worst + 1

    def _raw_params(self) -> SimpleNamespace:
        p = dict(fx=self.fx, fy=self.fy, cx=self.cx, cy=self.cy, skew=self.skew)
        p.update({n: 0.0 for n in OPENCV_COEFFS})
        names = {"opencv": OPENCV_COEFFS, "fisheye": FISHEYE_COEFFS}.get(self.model, ())
        p.update(dict(zip(names, self.dist)))
        return SimpleNamespace(**p)

    def _fold_limit(self) -> float:
        """The monotonic region: r^2 limit (opencv), theta limit (fisheye), inf (pinhole).

        Searches along 120 directions (1500 radii each, 0.06 degree steps) for the first radius where the distortion's Jacobian
        determinant is <= 0; if that fold lands at a pixel inside the image, the camera is
        rejected.
        """
        if self.model == "pinhole":
            return math.inf
        p = self._raw_params()
        phi = np.linspace(0.0, 2 * np.pi, 120, endpoint=False)[:, None]
        if self.model == "fisheye":
            theta = np.linspace(0.0, np.pi, 4001)[1:]
            dth = fisheye_dtheta_d(theta, p)
            fold = np.flatnonzero(dth <= 0)
            if fold.size == 0:
                return math.pi
            t_fold = theta[fold[0]]
            td = fisheye_theta_d(t_fold, p)
            xd, yd = td * np.cos(phi[:, 0]), td * np.sin(phi[:, 0])
            self._reject_if_inside(xd, yd, p, f"theta = {math.degrees(t_fold):.2f} deg")
            return float(theta[fold[0] - 1]) if fold[0] > 0 else 0.0
        ang = np.radians(np.linspace(0.0, _MAX_PERSPECTIVE_ANGLE_DEG, 1501)[1:])[None, :]
        r = np.tan(ang)
        x, y = r * np.cos(phi), r * np.sin(phi)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            xd, yd, j11, j12, j21, j22 = distort_opencv_jacobian_xy(x, y, p)
            det = j11 * j22 - j12 * j21
        folded = ~(det > 0)
        first = np.where(folded.any(axis=1), folded.argmax(axis=1), -1)
        rows = np.flatnonzero(first >= 0)
        if rows.size == 0:
            return math.inf
        self._reject_if_inside(xd[rows, first[rows]], yd[rows, first[rows]], p, "the Jacobian determinant reaches 0")
        r_prev = np.where(first[rows] > 0, r[0, np.maximum(first[rows] - 1, 0)], 0.0)
        return float(np.min(r_prev) ** 2)

    def _reject_if_inside(self, xd, yd, p, what: str):
        xd, yd = np.atleast_1d(xd), np.atleast_1d(yd)
        u = p.fx * xd + p.skew * yd + p.cx
        v = p.fy * yd + p.cy
        inside = (u >= -0.5) & (u <= self.width - 0.5) & (v >= -0.5) & (v <= self.height - 0.5)
        if inside.any():
            i = np.argmax(inside)
            raise ValueError(
                f"{self.model} distortion {self.coefficients()} folds over inside the {self.width}x{self.height}"
                f" image: {what} at pixel ({u[i]:.1f}, {v[i]:.1f}); the mapping is not monotonic in radius there")

    def field_of_view_deg(self) -> dict:
        """Valid field of view in degrees: ``horizontal`` and ``vertical`` (through the principal
        point, edge to edge), ``diagonal`` (corner to corner), and ``max_off_axis`` (the largest
        angle between any border ray and the optical axis)."""
        W, H = self.width, self.height
        edge = np.array([[-0.5, self.cy], [W - 0.5, self.cy], [self.cx, -0.5], [self.cx, H - 0.5],
                         [-0.5, -0.5], [W - 0.5, H - 0.5]])
        d = self.unproject_unit(edge)
        ang = lambda a, b: math.degrees(math.atan2(np.linalg.norm(np.cross(a, b)), float(np.dot(a, b))))
        border = self.unproject_unit(_pixel_grid_border_and_interior(W, H, max(W, H)))
        off = np.degrees(np.arctan2(np.linalg.norm(border[:, :2], axis=1), border[:, 2]))
        return {"horizontal": ang(d[0], d[1]), "vertical": ang(d[2], d[3]),
                "diagonal": ang(d[4], d[5]), "max_off_axis": float(np.max(off))}

    # ----- COLMAP
    def to_colmap(self) -> tuple[str, list[float]]:
        """(COLMAP model name, params) with COLMAP's pixel convention (cx, cy + 0.5).

        pinhole -> PINHOLE; opencv with only k1, k2, p1, p2 -> OPENCV, with k3..k6 ->
        FULL_OPENCV; fisheye -> OPENCV_FISHEYE. COLMAP has no skew and no thin-prism terms on a
        perspective model: those raise ValueError.
        """
        from scenegen.conventions import colmap_from_opencv_pixels

        if self.skew != 0.0:
            raise ValueError("COLMAP camera models have no skew; this camera has skew != 0")
        cx, cy = colmap_from_opencv_pixels([self.cx, self.cy])
        base = [self.fx, self.fy, float(cx), float(cy)]
        if self.model == "pinhole":
            return "PINHOLE", base
        if self.model == "fisheye":
            return "OPENCV_FISHEYE", base + list(self.dist)
        if any(self.dist[8:]):
            raise ValueError("COLMAP has no perspective model with thin-prism terms s1..s4")
        if any(self.dist[4:8]):
            return "FULL_OPENCV", base + list(self.dist[:8])
        return "OPENCV", base + list(self.dist[:4])

    @classmethod
    def from_colmap(cls, model_name: str, width: int, height: int, params) -> "Camera":
        """Inverse of :meth:`to_colmap` (also SIMPLE_PINHOLE, SIMPLE_RADIAL, RADIAL)."""
        from scenegen.conventions import opencv_from_colmap_pixels

        p = [float(x) for x in params]
        if model_name in ("SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL"):
            f, cx, cy, *k = p
            fx = fy = f
            dist = {"SIMPLE_PINHOLE": (), "SIMPLE_RADIAL": (k[0], 0, 0, 0), "RADIAL": (k[0], k[1], 0, 0)}[model_name]
        else:
            fx, fy, cx, cy, *dist = p
        cx, cy = opencv_from_colmap_pixels([cx, cy])
        models = {"SIMPLE_PINHOLE": "pinhole", "PINHOLE": "pinhole", "SIMPLE_RADIAL": "opencv", "RADIAL": "opencv",
                  "OPENCV": "opencv", "FULL_OPENCV": "opencv", "OPENCV_FISHEYE": "fisheye"}
        if model_name not in models:
            raise ValueError(f"unsupported COLMAP camera model {model_name!r}; supported: {sorted(models)}")
        model = models[model_name]
        if model == "opencv" and not any(dist):
            model, dist = "pinhole", ()
        return cls(model, width, height, fx, fy, float(cx), float(cy), 0.0, tuple(dist))



def _newton_until_converged(state, residual_px, step):
    """Iterate ``step`` from ``state`` until every point's residual (px) is <= UNDISTORT_TOL_PX.

    Returns (final state, converged mask, the iteration count the slowest converged point needed).
    """
    done = None
    worst = 0
    for it in range(MAX_UNDISTORT_ITERATIONS + 1):
        res = residual_px(state)
        done = np.zeros(res.shape, bool) if done is None else done
        newly = ~done & (res <= UNDISTORT_TOL_PX)
        if newly.any():
            worst = it
        done |= newly
        if done.all():
            break
        state = step(state)
    return state, done, worst
