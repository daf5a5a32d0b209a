"""N-step phase-shift decoding with hierarchical temporal unwrapping (Srinivasan, Liu and
Halioua, Appl. Opt. 1984; Huntley and Saldner, Appl. Opt. 1993; Zuo et al., "Temporal phase
unwrapping algorithms for fringe projection profilometry", Opt. Lasers Eng. 2016, sec. 3.2).

Frames follow :mod:`scenegen.geometry.sl_codes`: per period ``p`` (coarsest first, the coarsest
covering the axis), N frames ``A + B cos(phi - 2 pi k / N)`` with ``phi = 2 pi (u + 0.5) / p``.
Each period's wrapped phase comes from the N-step formula; the coarsest gives the coordinate
directly and each finer phase is unwrapped against the coarser coordinate, so the finest period
sets the precision and the ratio of successive periods the robustness (a period count is wrong
once the coarser coordinate errs by more than half the finer period).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from scenegen.geometry.sl_codes import unwrap_temporal, wrapped_phase


@dataclass(frozen=True)
class DecodedPhase:
    """``coord_px`` (H, W) float64 continuous projector coordinate, NaN where none;
    ``modulation`` (H, W) the finest period's B (image units); ``valid`` (H, W) bool."""

    coord_px: np.ndarray
    modulation: np.ndarray
    valid: np.ndarray


def decode_phase(frames, *, periods_px, shifts_rad, length_px: int, min_modulation: float,
                 mask=None) -> DecodedPhase:
    """Decode (F, N, H, W) frames (F periods, coarsest first; N steps with ``shifts_rad``) into
    projector coordinates. Pixels whose modulation B of any period is below ``min_modulation``,
    outside ``mask`` or unwrapped outside ``[-0.5, length - 0.5)`` get NaN."""
    f = np.asarray(frames, dtype=np.float64)
    if f.ndim != 4 or f.shape[0] != len(periods_px) or f.shape[1] != len(shifts_rad):
        raise InputError(f"frames must be (periods, steps, H, W) = ({len(periods_px)}, {len(shifts_rad)}, H, W), "
                         f"got {f.shape}")
    wrapped, mods = zip(*(wrapped_phase(f[i], shifts_rad) for i in range(f.shape[0])))
    coord = unwrap_temporal(np.stack(wrapped), periods_px)
    valid = np.min(np.stack(mods), axis=0) >= min_modulation
    valid &= (coord >= -0.5) & (coord < length_px - 0.5)
    if mask is not None:
        valid &= np.asarray(mask, dtype=bool)
    return DecodedPhase(np.where(valid, coord, np.nan), mods[-1], valid)
