"""The calibrated camera: model, image size and intrinsics, OpenCV conventions (numpy).

Formulas, parameter orders, the validity rules and the undistortion iteration count:
:mod:`scenegen.geometry.camera` (package docstring). Per-model behaviour comes from the registry
(:mod:`.models`); conversions to OpenCV and COLMAP from :mod:`.interop`.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from scenegen.geometry.camera import interop
from scenegen.geometry.camera.models import ALL_COEFFS, camera_model, project_xyz, unproject_uv
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.camera.validity import measure_undistortion, pixel_grid_border_and_interior


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
    mask_beyond_fold: bool = False  # opt-in: a distortion that folds inside the image is
    # accepted; pixels beyond the fold radius get no ray (NaN), see :meth:`no_ray_mask`
    # derived at construction (not part of equality)
    undistort_iterations: int = field(default=0, init=False, compare=False)
    limit: float = field(default=math.inf, init=False, compare=False, repr=False)

    def __post_init__(self):
        model = camera_model(self.model)
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
        object.__setattr__(self, "dist", self._normalised_dist(model, self.dist))
        if self.mask_beyond_fold and self.model not in ("opencv", "pinhole"):  # pinhole: never folds
            raise ValueError(f"mask_beyond_fold is for the opencv model's polynomial, not {self.model!r}")
        limit, iterations = self._validate_and_measure(model)
        object.__setattr__(self, "limit", limit)
        object.__setattr__(self, "undistort_iterations", iterations)

    # ----- construction
    @staticmethod
    def _normalised_dist(model, dist) -> tuple:
        d = tuple(float(c) for c in (() if dist is None else np.asarray(dist, float).ravel()))
        if not all(math.isfinite(c) for c in d):
            raise ValueError(f"distortion coefficients must be finite, got {d}")
        return model.normalise_dist(model.name, d)

    @classmethod
    def from_opencv(cls, K, dist, size) -> "Camera":
        """From an OpenCV camera matrix K (3x3, skew in K[0, 1]), distortion vector and (W, H).
        The vector has one of OpenCV's lengths (4, 5, 8, 12, 14) even when every coefficient is 0
        (it then is a pinhole): ValueError otherwise."""
        d = () if dist is None else tuple(np.asarray(dist, float).ravel())
        if d:
            camera_model("opencv").normalise_dist("opencv", d)
        return cls(*interop.opencv_camera_args(K, dist, size))

    @classmethod
    def from_opencv_fisheye(cls, K, D, size, alpha: float = 0.0) -> "Camera":
        """From ``cv2.fisheye`` data: K, D = (k1, k2, k3, k4), (W, H) and skew ``alpha``."""
        return cls(*interop.opencv_fisheye_camera_args(K, D, size, alpha))

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
        """Distortion coefficients by name, in the model's order."""
        return dict(zip(camera_model(self.model).coefficients, self.dist))

    def params(self) -> SimpleNamespace:
        """Plain-float parameters for the ``*_xy`` arithmetic (the Mitsuba sensor makes opaque
        Dr.Jit copies of these)."""
        return SimpleNamespace(**{**vars(self._raw_params()), "limit": self.limit})

    def to_opencv(self) -> tuple[np.ndarray, np.ndarray]:
        """(K, dist) for OpenCV: ``cv2.projectPoints`` (opencv/pinhole; note OpenCV ignores skew
        there) or ``cv2.fisheye`` (fisheye; pass ``alpha = skew / fx``). The dist vector is the
        shortest OpenCV length (5, 8 or 12) that keeps every non-zero coefficient."""
        return camera_model(self.model).to_opencv(self)

    def with_size(self, width: int, height: int) -> "Camera":
        return Camera(self.model, width, height, self.fx, self.fy, self.cx, self.cy, self.skew, self.dist,
                      self.mask_beyond_fold)

    def no_ray_mask(self) -> np.ndarray:
        """(H, W) bool: pixel centres beyond the distortion's fold radius, which get no ray (all
        False unless ``mask_beyond_fold``)."""
        return _no_ray_mask(self)

    def to_dict(self) -> dict:
        """JSON form (cameras.json): model parameters plus K and OpenCV's dist for other readers."""
        K, d = self.to_opencv()
        return {
            "model": self.model, "width": self.width, "height": self.height,
            "fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy, "skew": self.skew,
            "dist": list(self.dist), "coefficients": self.coefficients(),
            "K": K.tolist(), "opencv_dist": d.tolist(),
            "pixel_convention": "opencv: centre of the top-left pixel is (0, 0)",
            **({"mask_beyond_fold": True, "pixels_beyond_fold": int(self.no_ray_mask().sum())}
               if self.mask_beyond_fold else {}),
        }

    @classmethod
    def from_dict(cls, d: dict) -> "Camera":
        return cls(d["model"], d["width"], d["height"], d["fx"], d["fy"], d["cx"], d["cy"],
                   d.get("skew", 0.0), tuple(d.get("dist", ())), bool(d.get("mask_beyond_fold", False)))

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
    def _validate_and_measure(self, model) -> tuple[float, int]:
        p = self._raw_params()
        limit = model.fold_limit(p, self.width, self.height, f"{self.model} distortion {self.coefficients()}")
        if model.undistortion is None:
            return limit, 0
        p.limit = limit
        return limit, measure_undistortion(model.undistortion, p, self.width, self.height, self.model)

    def _raw_params(self) -> SimpleNamespace:
        p = dict(fx=self.fx, fy=self.fy, cx=self.cx, cy=self.cy, skew=self.skew,
                 mask_beyond_fold=self.mask_beyond_fold)
        p.update({n: 0.0 for n in ALL_COEFFS})
        p.update(self.coefficients())
        return SimpleNamespace(**p)

    def field_of_view_deg(self) -> dict:
        """Valid field of view in degrees: ``horizontal`` and ``vertical`` (through the principal
        point, edge to edge), ``diagonal`` (corner to corner), and ``max_off_axis`` (the largest
        angle between any border ray and the optical axis)."""
        W, H = self.width, self.height
        edge = np.array([[-0.5, self.cy], [W - 0.5, self.cy], [self.cx, -0.5], [self.cx, H - 0.5],
                         [-0.5, -0.5], [W - 0.5, H - 0.5]])
        d = self.unproject_unit(edge)
        ang = lambda a, b: math.degrees(math.atan2(np.linalg.norm(np.cross(a, b)), float(np.dot(a, b))))
        border = self.unproject_unit(pixel_grid_border_and_interior(W, H, max(W, H)))
        off = np.degrees(np.arctan2(np.linalg.norm(border[:, :2], axis=1), border[:, 2]))
        return {"horizontal": ang(d[0], d[1]), "vertical": ang(d[2], d[3]),
                "diagonal": ang(d[4], d[5]), "max_off_axis": float(np.max(off))}

    # ----- COLMAP
    def to_colmap(self) -> tuple[str, list[float]]:
        """(COLMAP model name, params) with COLMAP's pixel convention (cx, cy + 0.5): pinhole ->
        PINHOLE; opencv -> OPENCV (k1, k2, p1, p2 only) or FULL_OPENCV; fisheye -> OPENCV_FISHEYE.
        COLMAP has no skew and no thin-prism terms on a perspective model: those raise ValueError."""
        return camera_model(self.model).to_colmap(self)

    @classmethod
    def from_colmap(cls, model_name: str, width: int, height: int, params) -> "Camera":
        """Inverse of :meth:`to_colmap` (also SIMPLE_PINHOLE, SIMPLE_RADIAL, RADIAL)."""
        return cls(*interop.colmap_camera_args(model_name, width, height, params))


@functools.lru_cache(maxsize=16)
def _no_ray_mask(camera: Camera) -> np.ndarray:
    if not camera.mask_beyond_fold:
        return np.zeros((camera.height, camera.width), bool)
    d = camera.unproject_unit(pixel_centers(camera.width, camera.height).reshape(-1, 2))
    mask = ~np.isfinite(d[:, 0]).reshape(camera.height, camera.width)
    mask.flags.writeable = False
    return mask
