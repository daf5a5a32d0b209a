"""Depth from focus on a dataset's focus stacks (:func:`recon_eval.readers.focus.focus_stacks`),
scored with the Eigen depth metrics (:func:`recon_eval.metrics.depth.eigen_depth_metrics`) without
alignment (the focus distances are calibrated) and with per-image median scaling (the scale
ambiguity of an uncalibrated focus sweep), over all objects and per object.

* ``sml``: Nayar and Nakagawa's sum-modified-Laplacian focus measure (PAMI 1994):
  ML = |2 I - I(u-s) - I(u+s)| + |2 I - I(v-s) - I(v+s)| with step s = 1 on the grey linear image,
  summed over a (2 ``window`` + 1)^2 window; per pixel the image of largest focus measure, refined
  by their Gaussian interpolation through it and its two neighbours in the sweep, done in inverse
  depth (1 / focus distance: the variable the blur is linear in, and the one the stack steps evenly
  in). Peaks at the ends of the stack are not interpolated.

Raw output: ``<stack>/depth.npy`` (H, W) float32 metres, ``<stack>/index.npy`` (H, W) float32 (the
interpolated peak, in stack positions nearest first); read back and scored.
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import uniform_filter

from recon_eval.metrics.depth import eigen_depth_metrics
from recon_eval.readers.focus import FocusStack, focus_stacks
from recon_eval.runners.common import RunOutput, out_path
from scenegen.dataset.codecs import encode_npy
from scenegen.dataset.files import atomic_write_bytes


def sum_modified_laplacian(image: np.ndarray, window: int) -> np.ndarray:
    """(H, W) SML focus measure of an (H, W) image (edges replicated)."""
    p = np.pad(image, 1, mode="edge")
    c = p[1:-1, 1:-1]
    ml = np.abs(2 * c - p[1:-1, :-2] - p[1:-1, 2:]) + np.abs(2 * c - p[:-2, 1:-1] - p[2:, 1:-1])
    return uniform_filter(ml, size=2 * window + 1, mode="nearest") * (2 * window + 1) ** 2


def depth_from_focus(stack_images: np.ndarray, focus_distance_m: np.ndarray, window: int) -> tuple[np.ndarray, np.ndarray]:
    """((H, W) depth in metres, (H, W) interpolated peak position) of a (K, H, W) stack sorted by
    focus distance (module docstring)."""
    F = np.stack([sum_modified_laplacian(im, window) for im in stack_images])  # (K, H, W)
    K = len(F)
    k = np.argmax(F, axis=0)
    kk = np.clip(k, 1, K - 2)
    lf = np.log(np.maximum(F, 1e-300))
    a, b, c = (np.take_along_axis(lf, (kk + o)[None], 0)[0] for o in (-1, 0, 1))
    denom = a - 2 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(denom < 0, (a - c) / (2 * denom), 0.0)
    delta = np.where((k == kk), np.clip(delta, -0.5, 0.5), 0.0)
    pos = kk + delta if K >= 3 else k.astype(np.float64)
    pos = np.where(k == kk, pos, k)
    inv = 1.0 / focus_distance_m
    inv_at = np.interp(pos, np.arange(K), inv)
    return 1.0 / inv_at, pos


def _scores(s: FocusStack, depth: np.ndarray) -> tuple[dict, dict]:
    results, metrics = {}, {}
    groups = {"all": s.object_id > 0, **{n: s.object_id == oid for n, oid in s.objects.items()}}
    for name, m in groups.items():
        if not m.any():
            continue
        g = np.where(m, s.depth_z, np.nan)
        for align in ("none", "median"):
            r = eigen_depth_metrics([depth], [g], alignment=align)
            results[f"{name}.{align}"] = r
            if align == "none" or name == "all":
                metrics.update({f"{name}.{align}.abs_rel": r.abs_rel, f"{name}.{align}.a1": r.a1})
            if name == "all":
                metrics[f"{name}.{align}.rmse_m"] = r.rmse_m
    return results, metrics


def sml(ds, out_dir, options) -> RunOutput:
    window = int(options.get("window", 4))
    results, metrics, raw = {}, {}, []
    stacks = focus_stacks(ds.root)
    for i, s in enumerate(stacks):
        depth, pos = depth_from_focus(s.images_linear, s.focus_distance_m, window)
        prefix = f"stack{i}" if len(stacks) > 1 else "focus"
        for name, arr in (("depth.npy", depth), ("index.npy", pos)):
            atomic_write_bytes(out_path(out_dir, f"{prefix}/{name}"), encode_npy(arr.astype(np.float32)))
            raw.append(f"{prefix}/{name}")
        back = np.load(out_path(out_dir, f"{prefix}/depth.npy")).astype(np.float64)
        r, mt = _scores(s, back)
        tag = (lambda k: f"{prefix}.{k}") if len(stacks) > 1 else (lambda k: k)
        results.update({tag(k): v for k, v in r.items()})
        metrics.update({tag(k): v for k, v in mt.items()})
    notes = {"stacks": [list(s.views) for s in stacks], "window": window,
             "focus_distances_m": [s.focus_distance_m.tolist() for s in stacks]}
    return RunOutput(results, metrics, raw, notes)
