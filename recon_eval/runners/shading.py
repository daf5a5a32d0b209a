"""Shape from shading on a dataset's single images lit by one directional light
(:func:`recon_eval.readers.photometric.photometric_sets` with one view), scored with DiLiGenT's
normal metrics and the depth error up to the integration constant (:mod:`recon_eval.metrics.normals`).

* ``ikeuchi_horn``: Ikeuchi and Horn's iterative scheme (Artificial Intelligence 17, 1981) with
  the occluding boundary as its boundary condition, made integrable at every iteration by Frankot
  and Chellappa's projection (PAMI 1988, who applied it to shape from shading in this way).
  Lambertian, the light direction and the albedo known. The start is the silhouette's own shape:
  h0 = sqrt(d (2 d_max - d)), d the distance (px) to the silhouette boundary (a sphere for a
  disc: slopes that grow to the rim, where the true normal is perpendicular to the view). Each
  iteration: p, q <- local 3x3 mean + ``step`` (E - R(p, q)) dR/d(p, q), with R = rho max(0,
  -p s_x + q s_y + s_z) / sqrt(1 + p^2 + q^2) (DiLiGenT's axes: normal (-p, q, 1) / N for p =
  dh/du, q = dh/dv, v down), clipped to |p|, |q| <= 20, then h = Frankot-Chellappa(p, q) and p, q
  its central differences (0 off the object). E is the image divided by the light's intensity per
  channel, averaged over the channels; rho is the median of the albedo truth over the object (the
  method's "known albedo").

Raw output: ``sfs/normals.npy`` (H, W, 3) float32 in DiLiGenT's axes (0 off the object),
``sfs/depth.npy`` (H, W) float32 metres (orthographic, at the median truth depth), read back and
scored; ``silhouette.*`` scores the start alone (what the shading adds).
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import distance_transform_edt, uniform_filter

from recon_eval.errors import NotApplicable
from recon_eval.metrics.normals import depth_up_to_offset, normal_metrics
from recon_eval.readers.photometric import photometric_sets
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.runners.photometric import frankot_chellappa
from scenegen.dataset.codecs import encode_npy
from scenegen.dataset.files import atomic_write_bytes
from scenegen.geometry.conventions import DILIGENT_FROM_OPENCV_CAM


def _normals(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    return np.stack([-p, q, np.ones_like(p)], axis=-1) / np.sqrt(1.0 + p * p + q * q)[..., None]


def _slopes(h: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.where(mask, np.gradient(h, axis=1), 0.0), np.where(mask, np.gradient(h, axis=0), 0.0)


def silhouette_height(mask: np.ndarray) -> np.ndarray:
    """(H, W) start height (px): sqrt(d (2 d_max - d)), d the distance to the silhouette's boundary."""
    d = distance_transform_edt(mask)
    return np.sqrt(np.clip(d * (2.0 * d.max() - d), 0.0, None))


def ikeuchi_horn(E: np.ndarray, albedo: float, light_diligent: np.ndarray, mask: np.ndarray, iterations: int,
                 step: float) -> tuple[np.ndarray, np.ndarray]:
    """((H, W) height in pixels toward the camera, (H, W, 3) unit normals in DiLiGenT's axes, 0 off
    ``mask``) from an (H, W) image E = rho max(0, n . s) (module docstring)."""
    sx, sy, sz = (float(c) for c in light_diligent / np.linalg.norm(light_diligent))
    h = silhouette_height(mask)
    p, q = _slopes(h, mask)
    for _ in range(iterations):
        N = np.sqrt(1.0 + p * p + q * q)
        dot = -p * sx + q * sy + sz
        e = np.where(mask, E - albedo * np.clip(dot, 0.0, None) / N, 0.0)
        Rp = albedo * (-sx / N - dot * p / N ** 3)
        Rq = albedo * (sy / N - dot * q / N ** 3)
        p = np.clip(np.where(mask, uniform_filter(p, 3) + step * e * Rp, 0.0), -20.0, 20.0)
        q = np.clip(np.where(mask, uniform_filter(q, 3) + step * e * Rq, 0.0), -20.0, 20.0)
        h = frankot_chellappa(p, q)
        p, q = _slopes(h, mask)
    return h, np.where(mask[..., None], _normals(p, q), 0.0)


def run(ds, out_dir, options) -> RunOutput:
    iterations = int(options.get("iterations", 200))
    step = float(options.get("step", 8.0))
    sets = [s for s in photometric_sets(ds.root, min_views=1) if np.isnan(s.positions_cam).all()]
    if not sets:
        raise NotApplicable(f"{ds.root}: no image lit by one directional light")
    s = sets[0]
    if s.albedo is None:
        raise ValueError(f"{ds.root}: shape from shading needs the albedo truth (spec truth.albedo)")
    mask = s.object_id > 0
    E = (s.images_linear[0] / s.intensities[0]).mean(axis=-1)
    rho = float(np.median(s.albedo[mask].mean(axis=-1)))
    light = DILIGENT_FROM_OPENCV_CAM @ s.directions_cam[0]
    h, n_dl = ikeuchi_horn(E, rho, light, mask, iterations, step)
    z_ref = float(np.nanmedian(s.depth_z[mask]))
    depth = np.where(mask, z_ref - h * z_ref / s.fx_px, np.nan)
    raw = []
    for name, arr in (("normals.npy", n_dl), ("depth.npy", depth)):
        atomic_write_bytes(out_path(out_dir, f"sfs/{name}"), encode_npy(arr.astype(np.float32)))
        raw.append(f"sfs/{name}")
    n_cv = np.load(out_path(out_dir, "sfs/normals.npy")).astype(np.float64) @ DILIGENT_FROM_OPENCV_CAM.T
    depth_back = np.load(out_path(out_dir, "sfs/depth.npy")).astype(np.float64)
    results, metrics = {}, {}
    for name, m in {"all": mask, **{k: s.object_id == v for k, v in s.objects.items()}}.items():
        if not m.any() or (name != "all" and len(s.objects) == 1):
            continue
        r = normal_metrics(s.normals_cam, n_cv, m)
        d = depth_up_to_offset(s.depth_z, depth_back, m)
        results[f"{name}.normals"], results[f"{name}.depth"] = r, d
        metrics.update({f"{name}.mean_ae_deg": r.mean_ae_deg, f"{name}.median_ae_deg": r.median_ae_deg,
                        f"{name}.within_20deg": r.within_20deg, f"{name}.depth_rel_rmse": d.rel_rmse})
    h0 = silhouette_height(mask)
    start = normal_metrics(s.normals_cam, _normals(*_slopes(h0, mask)) @ DILIGENT_FROM_OPENCV_CAM.T, mask)
    results["silhouette.normals"] = start
    metrics["silhouette.mean_ae_deg"] = start.mean_ae_deg
    notes = {"view": s.views[0], "iterations": iterations, "step": step, "albedo_used": rho,
             "normals_frame": "DiLiGenT: x right, y up, z toward the camera"}
    return RunOutput(results, metrics, raw, notes)
