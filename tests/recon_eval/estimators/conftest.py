"""An analytic projector-camera scene for the structured-light estimators: a tilted plane and a
sphere in front of it, every camera pixel centre's ray hit in closed form, its projector
coordinate by the projector's own model (scenegen.geometry.camera), the pattern sampled there."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.imaging.patterns import sample

PLANE_N = np.array([0.15, -0.1, 1.0]) / np.linalg.norm([0.15, -0.1, 1.0])  # plane n . X = PLANE_D
PLANE_D = 0.6
SPHERE_C = np.array([0.01, 0.0, 0.5])
SPHERE_R = 0.07


@dataclass(frozen=True)
class ProCam:
    camera: Camera
    cam_from_world: Rigid3
    projector: Camera
    proj_from_world: Rigid3
    points: np.ndarray  # (H, W, 3) world points of the pixel centres (NaN: no hit)
    uv: np.ndarray  # (H, W, 2) continuous projector coordinates of the points
    lit: np.ndarray  # (H, W) bool: the projector lights the point
    albedo: np.ndarray  # (H, W)

    def observe(self, seq, *, noise_sigma: float = 0.0, ambient: float = 0.05, seed: int = 0) -> np.ndarray:
        """(N, H, W) grey images of the sequence: albedo * (pattern where lit + ambient) + noise."""
        vals = sample(seq, self.uv).astype(np.float64)  # (N, H, W)
        img = self.albedo[None] * (np.where(self.lit[None], vals, 0.0) + ambient)
        if noise_sigma:
            img = img + np.random.default_rng(seed).normal(0.0, noise_sigma, img.shape)
        return img


def _sphere_t(o, d):
    """Nearest positive ray parameter of rays o + t d (unit d) on the sphere; inf where none."""
    w = np.broadcast_to(o - SPHERE_C, d.shape)
    b = np.einsum("...i,...i->...", d, w)
    disc = b * b - (np.einsum("...i,...i->...", w, w) - SPHERE_R ** 2)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc > 0) & (t > 1e-9), t, np.inf)


def build(camera: Camera, projector: Camera, proj_centre) -> ProCam:
    cam_from_world = Rigid3.identity()
    proj_from_world = look_at(proj_centre, [0.0, 0.0, 0.55], up=(0.0, -1.0, 0.0)).inverse()
    H, W = camera.height, camera.width
    d = camera.unproject_unit(pixel_centers(W, H).reshape(-1, 2))
    o = np.zeros(3)
    t_plane = PLANE_D / (d @ PLANE_N)
    t_sph = _sphere_t(o, d)
    on_sphere = t_sph < t_plane
    t = np.where(on_sphere, t_sph, t_plane)
    p = d * t[:, None]
    # projector visibility: the point's normal faces the projector; nothing (the sphere) between
    pc = np.asarray(proj_centre, float)
    normal = np.where(on_sphere[:, None], (p - SPHERE_C) / SPHERE_R, -PLANE_N)
    to_proj = pc - p
    dist = np.linalg.norm(to_proj, axis=1)
    dir_p = to_proj / dist[:, None]
    blocked = ~on_sphere & (_sphere_t(p + 1e-9 * dir_p, dir_p) < dist)
    uv, ok = projector.project(proj_from_world.apply(p), return_valid=True)
    inside = ok & (uv[:, 0] >= -0.5) & (uv[:, 0] < projector.width - 0.5) & (uv[:, 1] >= -0.5) & \
        (uv[:, 1] < projector.height - 0.5)
    lit = inside & (np.einsum("ij,ij->i", normal, dir_p) > 0) & ~blocked
    albedo = np.where(on_sphere, 0.7, 0.5) + 0.2 * np.cos(40 * p[:, 0])  # textured, 0.3..0.9
    return ProCam(camera, cam_from_world, projector, proj_from_world, p.reshape(H, W, 3), uv.reshape(H, W, 2),
                  lit.reshape(H, W), albedo.reshape(H, W))


@pytest.fixture(scope="session")
def procam() -> ProCam:
    """A 160 x 120 OpenCV camera with distortion, a 128 x 96 projector with distortion, skew and
    an off-centre principal point, 0.15 m apart."""
    camera = Camera("opencv", 160, 120, 150.0, 151.0, 80.3, 59.6, dist=(-0.05, 0.01, 0.001, -0.0005, 0.0))
    projector = Camera("opencv", 128, 96, 140.0, 139.0, 60.0, 70.0, skew=0.4, dist=(0.04, -0.01, 0.0, 0.0, 0.0))
    return build(camera, projector, (0.15, -0.02, 0.0))
