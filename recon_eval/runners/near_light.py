"""Near-light photometric stereo on a dataset's photometric sets lit by point lights (one per
image, calibrated positions and intensities from ``truth/<view>_lights.json``), scored like the
distant-light runner (:mod:`recon_eval.runners.photometric`).

* ``woodham_near``: Woodham's least squares with each pixel's own light vectors, alternated with the
  surface they depend on (the scheme of near-light methods such as Papadhimitri and Favaro, IJCV
  2014, in its simplest form). Start: every pixel at the median truth depth z0 (the distance
  photometric stereo is given, as for integration). Each iteration: the pixel's point X = z ray
  (the camera's own unprojection), l_k = (s_k - X) / r_k, attenuation 1 / r_k^2 (r_k = |s_k - X|);
  the image divided by the light's intensity (W/sr / pi) and by the attenuation, averaged over the
  channels, is rho (n . l_k); observations at or below ``shadow_threshold`` are left out and b = rho n
  solves the 3 x 3 normal equations sum_k l_k l_k^T b = sum_k E_k l_k; then the normals are
  integrated (Frankot-Chellappa, orthographic at z0) into the next depth, its constant chosen so
  that the object's median depth stays z0. ``iterations`` rounds; the
  first round (every pixel at z0: the lights' directions and fall-off as seen from one plane)
  is also scored, as ``plane.*``, to show what the surface's own geometry adds, and so is
  distant-light Woodham with each light's direction and fall-off taken at the object's centre
  (``distant.*``), what a distant-light method makes of these images.

Raw output: ``near/normals.npy`` (DiLiGenT's axes, 0 where no normal), ``near/albedo.npy``,
``near/depth.npy``, read back and scored per object and over all (DiLiGenT's metrics).
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.normals import normal_metrics
from recon_eval.readers.photometric import PhotometricSet, photometric_sets
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.runners.photometric import MIN_LIGHTS, depth_from_normals, score_set, woodham
from scenegen.dataset.codecs import encode_npy
from scenegen.dataset.files import atomic_write_bytes
from scenegen.geometry.conventions import DILIGENT_FROM_OPENCV_CAM, pixel_centers


def near_light_round(s: PhotometricSet, depth: np.ndarray, mask: np.ndarray,
                     threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """((H, W, 3) unit normals in the camera frame, 0 where unsolved; (H, W, 3) albedo, NaN where
    unsolved) with every pixel's point at ``depth`` (H, W) metres (module docstring)."""
    K, H, W, _ = s.images_linear.shape
    rays = s.camera.unproject(pixel_centers(W, H).reshape(-1, 2))  # (P, 3) on z = 1
    X = rays * depth.reshape(-1, 1)
    V = s.positions_cam[:, None, :] - X[None]  # (K, P, 3)
    r = np.linalg.norm(V, axis=2)
    L = V / r[..., None]
    obs = (s.images_linear / s.intensities[:, None, None, :]).reshape(K, -1, 3) * (r * r)[..., None]  # rho_c (n . l)
    E = obs.mean(axis=2)  # (K, P)
    w = (E > threshold) & mask.reshape(1, -1)
    A = np.einsum("kp,kpi,kpj->pij", w, L, L)
    b = np.einsum("kp,kp,kpi->pi", w, E, L)
    ok = (w.sum(axis=0) >= MIN_LIGHTS) & (np.abs(np.linalg.det(A)) > 1e-12)
    sol = np.zeros((H * W, 3))
    sol[ok] = np.linalg.solve(A[ok], b[ok][..., None])[..., 0]
    norm = np.linalg.norm(sol, axis=1)
    ok &= norm > 0
    n = np.zeros((H * W, 3))
    n[ok] = sol[ok] / norm[ok, None]
    shade = np.einsum("pi,kpi->kp", n, L) * w  # (K, P)
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.einsum("kp,kpc->pc", shade, obs) / np.sum(shade ** 2, axis=0)[:, None]
    rho[~ok] = np.nan
    return n.reshape(H, W, 3), rho.reshape(H, W, 3)


def woodham_near(ds, out_dir, options) -> RunOutput:
    threshold = float(options.get("shadow_threshold", 0.02))
    iterations = int(options.get("iterations", 4))
    sets = [s for s in photometric_sets(ds.root) if np.isfinite(s.positions_cam).all()]
    if not sets:
        raise NotApplicable(f"{ds.root}: no photometric stereo set under point lights")
    s = sets[0]
    mask = s.object_id > 0
    z0 = float(np.nanmedian(s.depth_z[mask]))
    depth = np.full(mask.shape, z0)
    first = None
    for _ in range(iterations):
        n_cv, albedo = near_light_round(s, depth, mask, threshold)
        first = n_cv if first is None else first
        d = depth_from_normals(n_cv @ DILIGENT_FROM_OPENCV_CAM.T, mask, z0 / s.fx_px, z0)
        depth = np.where(mask, d - np.nanmedian(d[mask]) + z0, z0)  # anchored: the object's median stays at z0
    files = {"normals.npy": n_cv @ DILIGENT_FROM_OPENCV_CAM.T, "albedo.npy": albedo,
             "depth.npy": np.where(mask, depth, np.nan)}
    raw = []
    for name, arr in files.items():
        atomic_write_bytes(out_path(out_dir, f"near/{name}"), encode_npy(arr.astype(np.float32)))
        raw.append(f"near/{name}")
    back = {name: np.load(out_path(out_dir, f"near/{name}")).astype(np.float64) for name in files}
    results, metrics = score_set(s, back["normals.npy"] @ DILIGENT_FROM_OPENCV_CAM.T, back["albedo.npy"], back["depth.npy"])
    plane = normal_metrics(s.normals_cam, first, mask)
    results["plane.normals"] = plane
    metrics["plane.mean_ae_deg"] = plane.mean_ae_deg
    # the distant-light approximation: each light's direction and fall-off from the object's centre
    centre = s.camera.unproject(np.array([[np.mean(np.nonzero(mask)[1]), np.mean(np.nonzero(mask)[0])]]))[0] * z0
    V = s.positions_cam - centre
    rc = np.linalg.norm(V, axis=1)
    n_far, _ = woodham(s.images_linear, V / rc[:, None], s.intensities / (rc * rc)[:, None], mask, threshold)
    distant = normal_metrics(s.normals_cam, n_far, mask)
    results["distant.normals"] = distant
    metrics["distant.mean_ae_deg"] = distant.mean_ae_deg
    notes = {"set": list(s.views), "iterations": iterations, "shadow_threshold": threshold, "start_depth_m": z0,
             "normals_frame": "DiLiGenT: x right, y up, z toward the camera"}
    return RunOutput(results, metrics, raw, notes)
