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

* ``stm`` (depth from defocus, two images: the nearest and farthest focus of a stack): Subbarao
  and Surya's spatial-domain transform (IJCV 13(3), 1994): for a locally cubic scene, an image
  blurred by a PSF of per-axis second moment s^2 is f + (s^2 / 2) lap f, so
  g1 - g2 = ((s1^2 - s2^2) / 2) lap g, g = (g1 + g2) / 2; a thin lens's disc of radius R has
  s^2 = R^2 / 4, R_i = K |1/Z_i - 1/Z| (K = fx A, px per dioptre), so
  D = R1^2 - R2^2 = 8 sum (g1 - g2) lap g / sum (lap g)^2 (least squares over a Gaussian window
  ``window_px``), and D / K^2 = a1^2 - a2^2 - 2 x (a1 - a2) is linear in x = 1/Z (a_i = 1/Z_i):
  one depth per pixel, no ambiguity. Pixels whose window has no texture (sum (lap g)^2 below
  1e-12) get no depth (NaN, scored as missing by the depth metrics' coverage).

Raw output: ``<stack>/depth.npy`` (H, W) float32 metres (and for ``sml`` ``<stack>/index.npy``,
the interpolated peak in stack positions, nearest first); read back and scored.
"""
from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter, uniform_filter

from recon_eval.errors import NotApplicable
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


def depth_from_defocus(g1: np.ndarray, g2: np.ndarray, focus1_m: float, focus2_m: float, k_px: float,
                       window_px: float) -> np.ndarray:
    """(H, W) depth (metres, NaN where untextured) from two (H, W) images focused at ``focus1_m``
    and ``focus2_m`` by one lens of ``k_px`` px of blur radius per dioptre (module docstring)."""
    g = 0.5 * (g1 + g2)
    p = np.pad(g, 1, mode="edge")
    lap = p[1:-1, :-2] + p[1:-1, 2:] + p[:-2, 1:-1] + p[2:, 1:-1] - 4 * g
    num = gaussian_filter((g1 - g2) * lap, window_px)
    den = gaussian_filter(lap * lap, window_px)
    D = np.where(den > 1e-12, 8.0 * num / np.where(den > 1e-12, den, 1.0), np.nan)
    a1, a2 = 1.0 / focus1_m, 1.0 / focus2_m
    x = (a1 * a1 - a2 * a2 - D / (k_px * k_px)) / (2.0 * (a1 - a2))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(x > 0, 1.0 / x, np.nan)


def stm(ds, out_dir, options) -> RunOutput:
    window = float(options.get("window_px", 4.0))
    results, metrics, raw = {}, {}, []
    stacks = focus_stacks(ds.root, min_views=2)
    for i, s in enumerate(stacks):
        if len(set(s.blur_px_per_dioptre.round(12))) != 1:
            raise NotApplicable(f"{ds.root}: the defocus pair {s.views[0]}, {s.views[-1]} has two different lenses")
        depth = depth_from_defocus(s.images_linear[0], s.images_linear[-1], float(s.focus_distance_m[0]),
                                   float(s.focus_distance_m[-1]), float(s.blur_px_per_dioptre[0]), window)
        prefix = f"stack{i}" if len(stacks) > 1 else "defocus"
        atomic_write_bytes(out_path(out_dir, f"{prefix}/depth.npy"), encode_npy(depth.astype(np.float32)))
        raw.append(f"{prefix}/depth.npy")
        r, mt = _scores(s, np.load(out_path(out_dir, f"{prefix}/depth.npy")).astype(np.float64))
        tag = (lambda k: f"{prefix}.{k}") if len(stacks) > 1 else (lambda k: k)
        results.update({tag(k): v for k, v in r.items()})
        metrics.update({tag(k): v for k, v in mt.items()})
        metrics[tag("coverage")] = r["all.none"].coverage
    notes = {"pairs": [[s.views[0], s.views[-1]] for s in stacks], "window_px": window}
    return RunOutput(results, metrics, raw, notes)


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
