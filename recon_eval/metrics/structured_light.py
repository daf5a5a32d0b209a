"""Structured-light scores: a decoder's per-camera-pixel codes against the truth codes, and its
reconstruction's depth against the truth depth.

* :func:`code_errors`: over the camera pixels the projector lights (truth ``projector_lit``):
  ``agreement`` = the fraction whose decoded code names the truth projector pixel on every coded
  axis (``floor(x + 0.5)``, :func:`scenegen.geometry.sl_codes.pixel_index`; undecoded pixels
  disagree), ``completeness`` = the fraction decoded; the code error ``|decoded - truth|`` in
  projector pixels (Euclidean over the axes) over the decoded lit pixels, against the truth codes
  (integers) or, when given, the continuous truth coordinates; ``false_decode_frac`` = decoded
  pixels the projector does not light (shadows, the background), over all decoded pixels;
  ``agreement_clear``: the agreement over the lit pixels whose footprint lies in one projector
  pixel (truth ``clear_column`` / ``clear_row``), where a code is unambiguous.
* :func:`depth_errors`: ``|z_est - z_truth|`` (metres, z along the camera axis) over pixels with
  both, completeness over the truth-valid pixels, and, with a per-pixel bound (the pattern's
  quantisation, :func:`recon_eval.estimators.structured_light.triangulate.column_quantisation_bound`
  for instance), the fraction within it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from scenegen.geometry.sl_codes import pixel_index


@dataclass(frozen=True)
class CodeResult:
    """A code map against the truth (module docstring); errors in projector pixels."""

    n_lit: int  # camera pixels the projector lights (truth)
    n_decoded: int  # of those, decoded
    completeness: float  # n_decoded / n_lit
    agreement: float  # lit pixels decoded to the truth projector pixel / n_lit
    agreement_decoded: float  # the same over the decoded lit pixels (n_decoded)
    mean_px: float  # code error over decoded lit pixels
    rms_px: float
    median_px: float
    p95_px: float
    max_px: float
    false_decode_frac: float  # decoded but not lit / decoded
    against: str  # 'codes' (integer truth) or 'coordinates' (continuous truth)
    n_clear: int = 0  # lit pixels whose footprint lies in one projector pixel on every axis (truth)
    agreement_clear: float = math.nan  # agreement over those (undecoded disagree); NaN without a clear mask


def _stats(e: np.ndarray) -> tuple[float, float, float, float, float]:
    if e.size == 0:
        return (math.nan,) * 5
    return (float(np.mean(e)), float(np.sqrt(np.mean(e ** 2))), float(np.median(e)),
            float(np.percentile(e, 95)), float(np.max(e)))


def code_errors(decoded_px, truth_code, lit, *, lengths_px, truth_px=None, clear=None) -> CodeResult:
    """Score ``decoded_px`` (H, W, A) float projector coordinates (NaN where undecoded) against
    ``truth_code`` (H, W, A) int projector pixels, ``lit`` (H, W) bool; ``lengths_px`` (A,) the
    projector's extent along each axis; ``truth_px`` (H, W, A) optional continuous truth;
    ``clear`` (H, W, A) optional bool: the pixel's footprint lies in one projector pixel along the
    axis (its code is unambiguous), for ``agreement_clear``."""
    dec = np.asarray(decoded_px, dtype=np.float64)
    code = np.asarray(truth_code)
    lit = np.asarray(lit, dtype=bool)
    if dec.ndim != 3 or dec.shape != code.shape or dec.shape[:2] != lit.shape or len(lengths_px) != dec.shape[2]:
        raise InputError(f"decoded {dec.shape}, truth codes {code.shape} and lit {lit.shape} must be (H, W, A) "
                         f"and (H, W) with {dec.shape[-1]} axis lengths")
    decoded = np.all(np.isfinite(dec), axis=2)
    idx = np.stack([pixel_index(dec[..., a], int(n)) for a, n in enumerate(lengths_px)], axis=2)
    agree = decoded & lit & np.all(idx == code, axis=2)
    ref = code.astype(np.float64) if truth_px is None else np.asarray(truth_px, dtype=np.float64)
    scored = decoded & lit
    err = np.linalg.norm(dec[scored] - ref[scored], axis=1)
    n_lit, n_dec = int(lit.sum()), int(scored.sum())
    n_all = int(decoded.sum())
    n_agree = int(agree.sum())
    n_clear, agreement_clear = 0, math.nan
    if clear is not None:
        cl = lit & np.all(np.asarray(clear, dtype=bool), axis=2)
        n_clear = int(cl.sum())
        agreement_clear = int((agree & cl).sum()) / n_clear if n_clear else math.nan
    return CodeResult(n_lit, n_dec, n_dec / n_lit if n_lit else math.nan, n_agree / n_lit if n_lit else math.nan,
                      n_agree / n_dec if n_dec else math.nan,
                      *_stats(err), int((decoded & ~lit).sum()) / n_all if n_all else math.nan,
                      "codes" if truth_px is None else "coordinates", n_clear, agreement_clear)


@dataclass(frozen=True)
class DepthErrorResult:
    """Depth of a reconstruction against the truth, metres."""

    n_valid: int  # truth-valid pixels scored
    n_estimated: int  # of those, with an estimate
    completeness: float  # n_estimated / n_valid
    mean_abs_m: float
    rms_m: float
    median_abs_m: float
    p95_abs_m: float
    max_abs_m: float
    within_bound_frac: float  # estimated pixels with |error| <= bound (NaN: no bound given)


def depth_errors(depth_est, depth_truth, valid, *, bound_m=None) -> DepthErrorResult:
    """``depth_est`` (H, W) metres (NaN where none) against ``depth_truth`` (H, W) over ``valid``
    (H, W) bool; ``bound_m`` (H, W) optional per-pixel error bound."""
    est = np.asarray(depth_est, dtype=np.float64)
    gt = np.asarray(depth_truth, dtype=np.float64)
    valid = np.asarray(valid, dtype=bool) & np.isfinite(gt)
    if est.shape != gt.shape or gt.shape != valid.shape:
        raise InputError(f"depth maps {est.shape}, {gt.shape} and mask {valid.shape} must have one shape")
    have = valid & np.isfinite(est)
    e = np.abs(est[have] - gt[have])
    within = math.nan
    if bound_m is not None and e.size:
        within = float(np.mean(e <= np.asarray(bound_m, dtype=np.float64)[have]))
    n_valid = int(valid.sum())
    return DepthErrorResult(n_valid, int(have.sum()), int(have.sum()) / n_valid if n_valid else math.nan,
                            *_stats(e), within)
