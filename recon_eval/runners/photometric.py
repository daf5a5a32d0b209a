"""Calibrated photometric stereo on a dataset's photometric stereo sets
(:func:`recon_eval.readers.photometric.photometric_sets`), scored with DiLiGenT's metrics
(:mod:`recon_eval.metrics.normals`) per object and over every object.

* ``woodham``: Woodham's least squares (Opt. Eng. 1980): each image is divided by its light's
  intensity per channel and averaged over the channels, I_k = rho (n . l_k); per pixel the
  observations with I_k <= ``shadow_threshold`` are taken as shadowed and left out, and
  b = rho n solves min sum_k (l_k . b - I_k)^2 over the rest (at least 3; else no normal, stored
  as 0 as DiLiGenT's methods do); n = b / |b|, and per channel rho_c = sum_k I_kc (n . l_k) /
  sum_k (n . l_k)^2 over the same observations.
* The normals are integrated into depth with Frankot and Chellappa's projection onto integrable
  surfaces (PAMI 1988) by numpy FFT, zero-padded to twice the image, gradients 0 off the
  objects, under an orthographic approximation: one pixel spans z / fx metres at the median truth
  depth z of the objects (the distance photometric stereo cannot measure); the constant of
  integration is the metric's alignment (:func:`recon_eval.metrics.normals.depth_up_to_offset`).

Raw output (the conventions of DiLiGenT's results: x right, y up, z toward the camera, 0 where no
normal): ``<set>/normals.npy`` (H, W, 3) float32, ``<set>/albedo.npy`` (H, W, 3) float32 (NaN where
none), ``<set>/depth.npy`` (H, W) float32 metres (NaN off the objects); read back and scored.
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.normals import albedo_metrics, depth_up_to_offset, normal_metrics
from recon_eval.readers.photometric import PhotometricSet, photometric_sets
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.tasks.headlines import normals_headline
from scenegen.dataset.codecs import encode_npy
from scenegen.dataset.files import atomic_write_bytes
from scenegen.geometry.conventions import DILIGENT_FROM_OPENCV_CAM

#: Least observations a pixel needs (three unknowns in b = rho n).
MIN_LIGHTS = 3


def woodham(images: np.ndarray, directions: np.ndarray, intensities: np.ndarray, mask: np.ndarray,
            shadow_threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """((H, W, 3) unit normals in the lights' frame, 0 where unsolved; (H, W, 3) albedo, NaN where
    unsolved) from (K, H, W, 3) linear images, (K, 3) unit directions toward the lights, (K, 3)
    light intensities and the (H, W) pixels to solve (module docstring)."""
    K, H, W, _ = images.shape
    obs = (images / intensities[:, None, None, :])  # (K, H, W, 3): rho_c (n . l_k)
    grey = obs.mean(axis=3).reshape(K, -1).T  # (P, K)
    lit = grey > shadow_threshold
    todo = mask.reshape(-1) & (lit.sum(axis=1) >= MIN_LIGHTS)
    normals = np.zeros((H * W, 3))
    albedo = np.full((H * W, 3), np.nan)
    obs_c = obs.reshape(K, -1, 3).transpose(1, 0, 2)  # (P, K, 3)
    idx = np.flatnonzero(todo)
    if len(idx) == 0:
        return normals.reshape(H, W, 3), albedo.reshape(H, W, 3)
    subsets, which = np.unique(lit[idx], axis=0, return_inverse=True)  # one system per subset of lights
    which = which.reshape(-1)
    order = np.argsort(which, kind="stable")
    bounds = np.searchsorted(which[order], np.arange(len(subsets) + 1))
    for j, use in enumerate(subsets):
        px = idx[order[bounds[j]:bounds[j + 1]]]
        L = directions[use]  # (k, 3)
        b = np.linalg.lstsq(L, grey[px][:, use].T, rcond=None)[0].T  # (n, 3)
        norm = np.linalg.norm(b, axis=1)
        ok = norm > 0
        n = b[ok] / norm[ok, None]
        shade = n @ L.T  # (n, k)
        rho = np.einsum("nk,nkc->nc", shade, obs_c[px[ok]][:, use]) / np.sum(shade ** 2, axis=1)[:, None]
        normals[px[ok]] = n
        albedo[px[ok]] = rho
    return normals.reshape(H, W, 3), albedo.reshape(H, W, 3)


def frankot_chellappa(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(H, W) height h whose gradient (dh/du along columns, dh/dv along rows, in pixels) is the
    least-squares integrable fit to (p, q) (Frankot and Chellappa 1988), mean 0; zero-padded to
    (2H, 2W) so the FFT's periodic wrap does not join opposite borders."""
    H, W = p.shape
    P = np.fft.fft2(p, s=(2 * H, 2 * W))
    Q = np.fft.fft2(q, s=(2 * H, 2 * W))
    wu = 2 * np.pi * np.fft.fftfreq(2 * W)[None, :]
    wv = 2 * np.pi * np.fft.fftfreq(2 * H)[:, None]
    denom = wu ** 2 + wv ** 2
    denom[0, 0] = 1.0
    Z = (-1j * wu * P - 1j * wv * Q) / denom
    Z[0, 0] = 0.0
    return np.real(np.fft.ifft2(Z))[:H, :W]


def depth_from_normals(normals_diligent: np.ndarray, mask: np.ndarray, metres_per_px: float,
                       depth_ref_m: float) -> np.ndarray:
    """(H, W) depth (metres, NaN off ``mask``) integrated from DiLiGenT-frame normals (module
    docstring): height h toward the camera has dh/du = -n_x / n_z, dh/dv = n_y / n_z (v down)."""
    nx, ny, nz = (normals_diligent[..., i] for i in range(3))
    good = mask & (nz > 1e-3)
    p = np.where(good, -nx / np.where(good, nz, 1.0), 0.0)
    q = np.where(good, ny / np.where(good, nz, 1.0), 0.0)
    h = frankot_chellappa(p, q) * metres_per_px
    return np.where(mask, depth_ref_m - h, np.nan)


def score_set(s: PhotometricSet, normals_cv: np.ndarray, albedo: np.ndarray, depth: np.ndarray) -> tuple[dict, dict]:
    """(results, headline metrics) of a set's normals (camera frame), albedo and depth, over all
    objects and per object: DiLiGenT's normal metrics, albedo up to scale, depth up to offset."""
    results, metrics = {}, {}
    groups = {"all": s.object_id > 0, **{name: s.object_id == oid for name, oid in s.objects.items()}}
    for name, m in groups.items():
        if not m.any():
            continue
        r = normal_metrics(s.normals_cam, normals_cv, m)
        results[f"{name}.normals"] = r
        metrics.update(normals_headline(r, name))
        if s.albedo is not None:
            a = albedo_metrics(s.albedo, albedo, m)
            results[f"{name}.albedo"] = a
            metrics[f"{name}.albedo_rel_mae"] = a.rel_mae
        d = depth_up_to_offset(s.depth_z, depth, m & np.isfinite(depth))
        results[f"{name}.depth"] = d
        metrics[f"{name}.depth_rel_rmse"] = d.rel_rmse
    return results, metrics


def run(ds, out_dir, options) -> RunOutput:
    threshold = float(options.get("shadow_threshold", 0.02))
    results, metrics, raw = {}, {}, []
    sets = [s for s in photometric_sets(ds.root) if np.isnan(s.positions_cam).all()]
    if not sets:
        raise NotApplicable(f"{ds.root}: no photometric stereo set under distant (directional) lights")
    for k, s in enumerate(sets):
        mask = s.object_id > 0
        n_cv, albedo = woodham(s.images_linear, s.directions_cam, s.intensities, mask, threshold)
        n_dl = n_cv @ DILIGENT_FROM_OPENCV_CAM.T
        z_ref = float(np.nanmedian(s.depth_z[mask]))
        depth = depth_from_normals(n_dl, mask, z_ref / s.fx_px, z_ref)
        prefix = f"set{k}" if len(sets) > 1 else "ps"
        files = {"normals.npy": n_dl.astype(np.float32), "albedo.npy": albedo.astype(np.float32),
                 "depth.npy": depth.astype(np.float32)}
        for name, arr in files.items():
            atomic_write_bytes(out_path(out_dir, f"{prefix}/{name}"), encode_npy(arr))
            raw.append(f"{prefix}/{name}")
        back = {name: np.load(out_path(out_dir, f"{prefix}/{name}")).astype(np.float64) for name in files}
        r, mt = score_set(s, back["normals.npy"] @ DILIGENT_FROM_OPENCV_CAM.T, back["albedo.npy"], back["depth.npy"])
        results.update({f"{prefix}.{key}" if len(sets) > 1 else key: v for key, v in r.items()})
        metrics.update({f"{prefix}.{key}" if len(sets) > 1 else key: v for key, v in mt.items()})
    notes = {"sets": [list(s.views) for s in sets], "shadow_threshold": threshold,
             "normals_frame": "DiLiGenT: x right, y up, z toward the camera"}
    return RunOutput(results, metrics, raw, notes)
