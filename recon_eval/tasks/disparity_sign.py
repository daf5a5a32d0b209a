"""A disparity of the wrong sign scores ~100 % bad with nothing else to see: the hint that says so.

recon_eval's disparity is ``u_left - u_right >= 0`` (docs/crossview.md, "Disparity sign"); a matcher or a
converter that writes ``u_right - u_left`` fails every pixel. The check compares the share of bad
pixels of the estimate with that of the negated estimate on the same pixels; it is a hint printed
on stderr, never a change of the score.
"""
from __future__ import annotations

import numpy as np

#: The bad-pixel threshold of the check, px (Middlebury's bad-2.0).
BAD_PX = 2.0
#: The hint is given when the estimate has at least this share of bad pixels ...
MIN_BAD = 0.5
#: ... and the negated estimate at most this fraction of the estimate's share.
NEGATED_RATIO = 0.5


def bad_share(est: np.ndarray, gt: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Share of the pixels with finite truth (within ``mask``) whose estimate is missing or off by
    more than :data:`BAD_PX`; NaN when there is no such pixel."""
    ok = np.isfinite(gt) if mask is None else np.isfinite(gt) & mask
    if not ok.any():
        return float("nan")
    with np.errstate(invalid="ignore"):
        good = np.abs(est[ok] - gt[ok]) <= BAD_PX
    return float(1.0 - np.mean(good))


def reversed_sign_hint(est: np.ndarray, gt: np.ndarray, mask: np.ndarray | None = None) -> str | None:
    """The hint for a disparity ``est`` that looks negated against ``gt`` (H, W) px, or None."""
    share, negated = bad_share(est, gt, mask), bad_share(-est, gt, mask)
    if not (share >= MIN_BAD and negated <= NEGATED_RATIO * share):
        return None
    return (f"{100 * share:.1f} % of the pixels are bad at {BAD_PX:g} px, {100 * negated:.1f} % with the disparity "
            f"negated: is its sign reversed? (disparity = u_left - u_right >= 0, docs/crossview.md)")
