"""Amplitude-modulated continuous-wave (AMCW) time of flight: the phase convention, the raw
correlation frames of a pixel, their decoding into depth, and dual-frequency unwrapping.

Convention (stated once here; docs/conventions.md "Time of flight"):

* A light path of total optical length ``L`` (emitter -> surfaces -> pixel, metres) at modulation
  frequency ``f`` (Hz) arrives with phase ``phi = 2 pi f L / c``. The emitter is co-located with
  the optical centre, so the direct path of a surface at range ``r`` has ``L = 2 r`` and
  ``phi = 4 pi f r / c``.
* A pixel's paths are summed as phasors: ``P = sum_paths w e^{i phi}`` (``w`` the path's
  radiance contribution), with ``S0 = sum_paths w`` its DC part.
* The raw frame at phase offset ``psi`` counts ``C(psi) = B + A cos(phi_P - psi)`` electrons, with
  ``B = k (S0 + ambient)``, ``A = k m |P|`` (``k``: electrons per unit of rendered radiance,
  ``m``: modulation contrast in [0, 1]); the four offsets are ``psi_j = j pi / 2``.
* Decoding: ``phi = atan2(C(pi/2) - C(3pi/2), C(0) - C(pi)) mod 2 pi``, range ``r = c phi / (4 pi f)``:
  the measured quantity is RANGE (distance from the optical centre along the pixel's ray, as
  :mod:`scenegen.geometry.conventions` defines it), not z-depth. It wraps at the ambiguity
  range ``c / (2 f)``: a surface at ``r`` reads ``r mod c / (2 f)``, its wrap count is
  ``floor(r / (c / (2 f)))``.
* Amplitude ``A = sqrt((C0 - C2)^2 + (C1 - C3)^2) / 2``, offset ``B = (C0 + C1 + C2 + C3) / 4``.

Dual-frequency unwrapping (:func:`unwrap_two`) picks the wrap counts ``(n1, n2)`` whose ranges
agree best within the unambiguous range of the pair, ``c / (2 gcd(f1, f2))``.
"""
from __future__ import annotations

import math

import numpy as np

#: c in m/s, exact (SI); the one statement of it (scenegen.imaging.exposure's photon energy uses it).
SPEED_OF_LIGHT_M_S = 299_792_458.0
#: The four phase offsets psi_j of the raw frames, radians.
PHASE_OFFSETS_RAD = (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi)


def ambiguity_range_m(freq_hz: float) -> float:
    """The range at which the phase of one modulation frequency wraps: c / (2 f), metres."""
    return SPEED_OF_LIGHT_M_S / (2.0 * float(freq_hz))


def phase_of_path_rad(path_length_m, freq_hz: float):
    """Phase 2 pi f L / c of a path of optical length L (metres), radians (not wrapped)."""
    return 2.0 * math.pi * float(freq_hz) * np.asarray(path_length_m, dtype=np.float64) / SPEED_OF_LIGHT_M_S


def raw_frames(dc, phasor_cos, phasor_sin, *, electrons_per_unit: float, contrast: float = 1.0,
               ambient=0.0) -> np.ndarray:
    """Mean electrons of the four raw frames (..., 4) of one frequency from a pixel's path sums
    (module docstring): ``dc`` = S0, ``phasor_cos`` / ``phasor_sin`` = Re / Im of P (all in
    rendered radiance units), ``ambient`` an extra DC in the same units."""
    dc = np.asarray(dc, np.float64)
    b = electrons_per_unit * (dc + np.asarray(ambient, np.float64))
    a_cos = electrons_per_unit * contrast * np.asarray(phasor_cos, np.float64)
    a_sin = electrons_per_unit * contrast * np.asarray(phasor_sin, np.float64)
    # A cos(phi - psi) = Re(P) cos psi + Im(P) sin psi
    return np.stack([b + a_cos * math.cos(p) + a_sin * math.sin(p) for p in PHASE_OFFSETS_RAD], axis=-1)


def decode_phase(frames) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(phase in [0, 2 pi), amplitude A, offset B) of raw frames (..., 4) at offsets
    :data:`PHASE_OFFSETS_RAD` (module docstring)."""
    c = np.asarray(frames, np.float64)
    re, im = c[..., 0] - c[..., 2], c[..., 1] - c[..., 3]
    phase = np.mod(np.arctan2(im, re), 2.0 * math.pi)
    phase = np.where(phase >= 2.0 * math.pi, 0.0, phase)  # mod of a tiny negative rounds up to 2 pi
    return phase, 0.5 * np.hypot(re, im), c.mean(axis=-1)


def range_from_phase_m(phase_rad, freq_hz: float) -> np.ndarray:
    """Wrapped range c phi / (4 pi f), metres, in [0, c / (2 f))."""
    return SPEED_OF_LIGHT_M_S * np.asarray(phase_rad, np.float64) / (4.0 * math.pi * float(freq_hz))


def wrap_count(range_m, freq_hz: float) -> np.ndarray:
    """How many ambiguity ranges lie below ``range_m``: floor(r / (c / 2 f)) (int64; -1 where the
    range is not finite)."""
    r = np.asarray(range_m, np.float64)
    n = np.floor(np.where(np.isfinite(r), r, 0.0) / ambiguity_range_m(freq_hz))
    return np.where(np.isfinite(r), n, -1).astype(np.int64)


def unambiguous_range_two_m(f1_hz: float, f2_hz: float) -> float:
    """Unambiguous range of a frequency pair: c / (2 gcd(f1, f2)) (frequencies whole hertz)."""
    if f1_hz != round(f1_hz) or f2_hz != round(f2_hz):
        raise ValueError(f"dual-frequency unwrapping needs whole-hertz frequencies, got {f1_hz}, {f2_hz}")
    return SPEED_OF_LIGHT_M_S / (2.0 * math.gcd(int(f1_hz), int(f2_hz)))


def unwrap_two(r1_m, r2_m, f1_hz: float, f2_hz: float, max_range_m: float | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Dual-frequency unwrapping: (range, n1, n2) from the wrapped ranges r1, r2 of frequencies
    f1, f2: over every n1 with r1 + n1 R1 < ``max_range_m`` (default: the pair's unambiguous
    range), n2 = round((r1 + n1 R1 - r2) / R2); the (n1, n2) whose two ranges differ least wins,
    its range is their weighted mean (weights f^2: the noise of a range goes as 1 / f). NaN in,
    NaN out."""
    r1, r2 = np.asarray(r1_m, np.float64), np.asarray(r2_m, np.float64)
    R1, R2 = ambiguity_range_m(f1_hz), ambiguity_range_m(f2_hz)
    top = unambiguous_range_two_m(f1_hz, f2_hz) if max_range_m is None else float(max_range_m)
    n1s = np.arange(int(math.ceil(top / R1 - 1e-9)), dtype=np.float64)  # not R1 x (1 + eps) beyond the top
    c1 = r1[..., None] + n1s * R1  # (..., K) candidate ranges of f1
    n2 = np.maximum(np.round((c1 - r2[..., None]) / R2), 0.0)
    err = np.abs(c1 - (r2[..., None] + n2 * R2))
    best = np.argmin(np.where(np.isfinite(err), err, np.inf), axis=-1)[..., None]
    n1b = np.take_along_axis(np.broadcast_to(n1s, c1.shape), best, -1)[..., 0]
    n2b = np.take_along_axis(n2, best, -1)[..., 0]
    w1, w2 = float(f1_hz) ** 2, float(f2_hz) ** 2
    rng = (w1 * (r1 + n1b * R1) + w2 * (r2 + n2b * R2)) / (w1 + w2)
    bad = ~(np.isfinite(r1) & np.isfinite(r2))
    return (np.where(bad, np.nan, rng), np.where(bad, -1, n1b).astype(np.int64),
            np.where(bad, -1, n2b).astype(np.int64))
