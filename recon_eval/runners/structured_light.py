"""Structured-light scanning on a dataset's projector-lit views
(:func:`recon_eval.readers.structured_light.projector_views`): decode, triangulate, score.

* ``gray`` (Lanman and Taubin's reference decoder): per bit the pattern against its inverse, a
  pixel unreliable when ``|difference|`` falls below ``threshold`` times its white - black
  contrast in any bit, or when that contrast is below ``min_contrast`` (linear units: the
  projector's shadow); Gray to binary; column (and row) codes
  (:mod:`recon_eval.estimators.structured_light.graycode`). Points: the camera ray against the
  decoded column (``triangulation: plane``) or against the projector ray of (column, row)
  (``rays``) (:mod:`recon_eval.estimators.structured_light.triangulate`), at the column's centre.
* ``phase``: N-step phase at each period, hierarchical temporal unwrapping
  (:mod:`recon_eval.estimators.structured_light.phase`), the ray against the continuous column.

Scores per view (``results``) and pooled over the views (``metrics``; the views' mean F-score
``fscore_mean``) (:mod:`recon_eval.metrics.structured_light`): code
agreement with the truth codes over the lit pixels, code error (projector px), completeness;
depth error against the truth depth and the fraction within each pixel's quantisation bound
(half a projector column along the ray); Tanks and Temples F-score at ``tau_m`` and Chamfer
against the truth points of the lit pixels (:mod:`recon_eval.metrics.pointcloud`).

Raw output per view: ``<view>/codes.npy`` (H, W, 2) float32 decoded projector (column, row),
NaN where none; ``<view>/cloud.ply`` the points (world frame, metres); read back and scored.
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.estimators.structured_light.graycode import contrast_mask, decode_axis
from recon_eval.estimators.structured_light.phase import decode_phase
from recon_eval.estimators.structured_light.triangulate import column_quantisation_bound, ray_column, ray_ray
from recon_eval.metrics.pointcloud import chamfer, tanks_and_temples
from recon_eval.metrics.structured_light import code_errors, depth_errors
from recon_eval.readers.ply import read_geometry, write_point_cloud_ply
from recon_eval.readers.structured_light import ProjectorView, projector_views
from recon_eval.runners.common import RunOutput, out_path
from scenegen.dataset.codecs import encode_npy
from scenegen.dataset.files import atomic_write_bytes
from scenegen.geometry.conventions import pixel_centers

TRIANGULATIONS = ("plane", "rays")


def _frames(pv: ProjectorView, kind: str) -> list[int]:
    return [i for i, f in enumerate(pv.frames) if f.kind == kind]


def decode_gray_view(pv: ProjectorView, threshold: float, min_contrast: float) -> np.ndarray:
    """(H, W, 2) float64 decoded (column, row), NaN where none (an axis not coded: NaN); Gray or
    plain binary code words, as the frames say."""
    white, black = (_frames(pv, k) for k in ("white", "black"))
    if not white or not black:
        raise NotApplicable(f"view {pv.view!r}: the Gray-code decoder needs the white and black frames")
    w, b = pv.images[white[0]], pv.images[black[0]]
    mask = contrast_mask(w, b, min_contrast)
    out = np.full(w.shape + (2,), np.nan)
    coded = [f.kind for f in pv.frames if f.kind in ("gray", "binary")]
    kind = coded[0] if coded else "gray"
    for a, axis in enumerate(("u", "v")):
        bits = sorted((f.bit, i) for i, f in enumerate(pv.frames) if f.kind == kind and f.axis == axis and not f.inverse)
        inv = sorted((f.bit, i) for i, f in enumerate(pv.frames) if f.kind == kind and f.axis == axis and f.inverse)
        if not bits:
            continue
        if [x for x, _ in bits] != [x for x, _ in inv]:
            raise NotApplicable(f"view {pv.view!r}: axis {axis}: every bit needs its inverse")
        length = pv.projector.width if axis == "u" else pv.projector.height
        d = decode_axis(pv.images[[i for _, i in bits]], pv.images[[i for _, i in inv]], length_px=length,
                        threshold=threshold * (w - b), gray=kind == "gray", mask=mask)
        out[..., a] = np.where(d.code >= 0, d.code, np.nan)
    return out


def decode_phase_view(pv: ProjectorView, min_modulation: float) -> np.ndarray:
    """(H, W, 2) float64 decoded continuous column (row NaN) of a phase-shift sequence."""
    idx = [i for i in _frames(pv, "phase") if pv.frames[i].axis == "u"]
    if not idx:
        raise NotApplicable(f"view {pv.view!r}: no phase-shift frames along the columns")
    periods = sorted({pv.frames[i].period_px for i in idx}, reverse=True)
    steps = sorted({pv.frames[i].step for i in idx})
    by = {(pv.frames[i].period_px, pv.frames[i].step): i for i in idx}
    frames = np.stack([[pv.images[by[(p, k)]] for k in steps] for p in periods])
    shifts = [pv.frames[by[(periods[0], k)]].shift_rad for k in steps]
    d = decode_phase(frames, periods_px=periods, shifts_rad=shifts, length_px=pv.projector.width,
                     min_modulation=min_modulation)
    out = np.full(d.coord_px.shape + (2,), np.nan)
    out[..., 0] = d.coord_px
    return out


def triangulate_view(pv: ProjectorView, codes: np.ndarray, triangulation: str):
    """(points (H, W, 3) world, NaN where none; bound (H, W) metres, NaN where none)."""
    H, W = codes.shape[:2]
    use_rays = triangulation == "rays" and np.isfinite(codes[..., 1]).any()
    ok = np.isfinite(codes[..., 0]) & (np.isfinite(codes[..., 1]) if use_rays else True)
    px = pixel_centers(W, H)[ok]
    args = (pv.camera, pv.cam_from_world, pv.projector, pv.projector_from_world, px)
    pts = np.full((H, W, 3), np.nan)
    bound = np.full((H, W), np.nan)
    if ok.any():
        pts[ok] = ray_ray(*args, codes[ok]) if use_rays else ray_column(*args, codes[ok][:, 0])
        bound[ok] = column_quantisation_bound(*args, np.floor(codes[ok][:, 0] + 0.5))
    return pts, bound


def score_view(pv: ProjectorView, codes: np.ndarray, points_world: np.ndarray, bound: np.ndarray, tau_m: float,
               continuous: bool) -> dict:
    """The results of one view (module docstring)."""
    axes = [a for a in (0, 1) if np.isfinite(codes[..., a]).any()] or [0]
    lengths = [(pv.projector.width, pv.projector.height)[a] for a in axes]
    res = {"codes": code_errors(codes[..., axes], pv.truth_code[..., axes], pv.lit, lengths_px=lengths,
                                clear=pv.clear[..., axes])}
    if continuous:
        res["codes_vs_coordinates"] = code_errors(codes[..., axes], pv.truth_code[..., axes], pv.lit,
                                                  lengths_px=lengths, truth_px=pv.truth_uv[..., axes])
    depth = pv.cam_from_world.apply(points_world)[..., 2]
    res["depth"] = depth_errors(depth, pv.depth_z, pv.lit, bound_m=bound)
    rec = points_world[np.all(np.isfinite(points_world), axis=2)]
    gt = pv.points_world[pv.lit & np.all(np.isfinite(pv.points_world), axis=2)]
    res["cloud"] = tanks_and_temples(rec, gt, tau_m)
    res["chamfer"] = chamfer(rec, gt)
    return res


def _run(ds, out_dir, options, decode, continuous: bool) -> RunOutput:
    triangulation = str(options.get("triangulation", "plane"))
    if triangulation not in TRIANGULATIONS:
        raise ValueError(f"triangulation must be one of {TRIANGULATIONS}, got {triangulation!r}")
    tau_m = float(options.get("tau_m", 0.001))
    views = projector_views(ds.root, source=str(options.get("source", "png")))
    results, metrics, raw, fscores = {}, {}, [], []
    pooled = {"dec": [], "code": [], "lit": [], "clear": [], "depth": [], "gt": [], "bound": []}
    for pv in views:
        codes = decode(pv)
        pts, bound = triangulate_view(pv, codes, triangulation)
        atomic_write_bytes(out_path(out_dir, f"{pv.view}/codes.npy"), encode_npy(codes.astype(np.float32)))
        ok = np.all(np.isfinite(pts), axis=2)
        write_point_cloud_ply(out_path(out_dir, f"{pv.view}/cloud.ply"), pts[ok])
        raw += [f"{pv.view}/codes.npy", f"{pv.view}/cloud.ply"]
        back_codes = np.load(out_path(out_dir, f"{pv.view}/codes.npy")).astype(np.float64)
        back = np.full(pts.shape, np.nan)
        back[ok] = read_geometry(out_path(out_dir, f"{pv.view}/cloud.ply")).vertices
        r = score_view(pv, back_codes, back, bound, tau_m, continuous)
        results.update({f"{pv.view}.{k}": v for k, v in r.items()})
        fscores.append(r["cloud"].fscore)
        for key, val in (("dec", back_codes), ("code", pv.truth_code), ("lit", pv.lit), ("clear", pv.clear),
                         ("depth", pv.cam_from_world.apply(back)[..., 2]), ("gt", pv.depth_z), ("bound", bound)):
            pooled[key].append(val.reshape(-1, *val.shape[2:]))
    cat = {k: np.concatenate(v)[:, None] for k, v in pooled.items()}  # (N, 1[, 2]): one image column
    axes = [a for a in (0, 1) if np.isfinite(cat["dec"][..., a]).any()] or [0]
    lengths = [(views[0].projector.width, views[0].projector.height)[a] for a in axes]
    results["all.codes"] = code_errors(cat["dec"][..., axes], cat["code"][..., axes], cat["lit"],
                                       lengths_px=lengths, clear=cat["clear"][..., axes])
    results["all.depth"] = depth_errors(cat["depth"], cat["gt"], cat["lit"], bound_m=cat["bound"])
    c, d = results["all.codes"], results["all.depth"]
    metrics.update({"code_agreement": c.agreement, "code_agreement_decoded": c.agreement_decoded,
                    "code_agreement_clear": c.agreement_clear,
                    "code_completeness": c.completeness, "code_err_mean_px": c.mean_px,
                    "depth_mean_abs_mm": 1e3 * d.mean_abs_m, "depth_rms_mm": 1e3 * d.rms_m,
                    "depth_p95_mm": 1e3 * d.p95_abs_m, "depth_within_bound": d.within_bound_frac,
                    "fscore_mean": float(np.mean(fscores))})
    notes = {"views": [pv.view for pv in views], "triangulation": triangulation, "tau_m": tau_m,
             "options": dict(options)}
    return RunOutput(results, metrics, raw, notes)


def gray(ds, out_dir, options) -> RunOutput:
    threshold = float(options.get("threshold", 0.1))
    min_contrast = float(options.get("min_contrast", 0.005))
    return _run(ds, out_dir, options, lambda pv: decode_gray_view(pv, threshold, min_contrast), False)


def phase(ds, out_dir, options) -> RunOutput:
    min_modulation = float(options.get("min_modulation", 0.005))
    return _run(ds, out_dir, options, lambda pv: decode_phase_view(pv, min_modulation), True)
