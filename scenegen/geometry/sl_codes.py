"""Structured-light codes, stated once: which projector pixel a continuous coordinate falls in,
the Gray and binary code words, the bit order, the phase of a phase-shift pattern, De Bruijn.

Everything a pattern generator (:mod:`scenegen.imaging.patterns`) and a decoder
(``recon_eval.runners``) must agree on lives here, in numpy, so both import the same rules.

* A projector is an inverse camera with the project's pixel convention
  (:mod:`scenegen.geometry.conventions`): the centre of projector column ``c`` is ``u = c``, and
  the column covers ``u`` in ``[c - 0.5, c + 0.5)``; the projector image spans
  ``[-0.5, W - 0.5) x [-0.5, H - 0.5)``. A projector shows a piecewise-constant image: every
  point of column ``c`` shows the pattern's value at ``c``.
* Codes: column ``c`` is coded by its own index (no centring offset, as OpenCV's
  ``structured_light::GrayCodePattern``), in ``bits_for(W)`` bits, most significant bit first:
  frame ``b`` of an axis shows bit ``n - 1 - b`` of the code word. A Gray code word is
  ``binary_to_gray(c)`` (reflected binary: ``c ^ (c >> 1)``).
* Phase shifting (N steps, period ``p`` projector pixels): step ``k`` shows
  ``I_k(c) = 0.5 + 0.5 cos(phi(c) - delta_k)``, ``phi(c) = 2 pi (c + 0.5) / p`` (phase 0 at the
  projector image's edge ``u = -0.5``, so a period ``p = W`` spans the image and no pixel centre
  sits on the wrap), ``delta_k = 2 pi k / N``, so
  ``phi = atan2(sum_k I_k sin delta_k, sum_k I_k cos delta_k)`` (Srinivasan et al. 1984) and the
  unwrapped phase ``phi`` gives the coordinate ``c = p phi / (2 pi) - 0.5``.
* The perfect decoder's code at a continuous coordinate is the index of the projector pixel that
  lights it, ``pixel_index(u) = floor(u + 0.5)`` (a float coordinate of that pixel's centre for
  phase shifting, which recovers the same integer); ``-1`` outside the projector image.
"""
from __future__ import annotations

import math

import numpy as np

#: Value of a pixel index outside the projector image (no projector pixel lights it).
OUTSIDE = -1


def bits_for(length_px: int) -> int:
    """Number of code bits for ``length_px`` projector pixels along an axis (>= 1)."""
    if length_px < 1:
        raise ValueError(f"projector axis length must be >= 1 px, got {length_px}")
    return max(1, math.ceil(math.log2(length_px)))


def binary_to_gray(code) -> np.ndarray:
    """Reflected binary Gray code of non-negative integers (any shape), int64."""
    c = np.asarray(code, dtype=np.int64)
    return c ^ (c >> 1)


def gray_to_binary(gray) -> np.ndarray:
    """Inverse of :func:`binary_to_gray` (prefix XOR of the bits), int64, any shape."""
    g = np.asarray(gray, dtype=np.int64)
    out = g.copy()
    shift = g >> 1
    while np.any(shift):
        out ^= shift
        shift >>= 1
    return out


def pixel_index(coord_px, length_px: int) -> np.ndarray:
    """int64 index of the projector pixel whose area contains the continuous coordinate
    (``floor(coord + 0.5)``), ``OUTSIDE`` (-1) outside ``[-0.5, length - 0.5)`` or for NaN."""
    coord = np.asarray(coord_px, dtype=np.float64)
    inside = np.isfinite(coord) & (coord >= -0.5) & (coord < length_px - 0.5)
    idx = np.floor(np.where(inside, coord, 0.0) + 0.5).astype(np.int64)
    return np.where(inside, np.minimum(idx, length_px - 1), OUTSIDE)


def code_bits(code, n_bits: int) -> np.ndarray:
    """(n_bits, ...) uint8 bits of integer code words, most significant first (frame order)."""
    c = np.asarray(code, dtype=np.int64)
    shifts = np.arange(n_bits - 1, -1, -1, dtype=np.int64).reshape((n_bits,) + (1,) * c.ndim)
    return ((c[None] >> shifts) & 1).astype(np.uint8)


def code_from_bits(bits) -> np.ndarray:
    """Integer code words (int64) from (n_bits, ...) bits, most significant first."""
    b = np.asarray(bits, dtype=np.int64)
    n_bits = b.shape[0]
    weights = (np.int64(1) << np.arange(n_bits - 1, -1, -1, dtype=np.int64)).reshape((n_bits,) + (1,) * (b.ndim - 1))
    return np.sum(b * weights, axis=0)


def phase_shifts_rad(n_steps: int) -> np.ndarray:
    """(N,) the phase shifts ``delta_k = 2 pi k / N`` of an N-step sequence, radians."""
    if n_steps < 3:
        raise ValueError(f"phase shifting needs >= 3 steps, got {n_steps}")
    return 2.0 * np.pi * np.arange(n_steps, dtype=np.float64) / n_steps


def phase_of(coord_px, period_px: float) -> np.ndarray:
    """Unwrapped phase ``2 pi (coord + 0.5) / period`` (radians) of projector coordinates."""
    return 2.0 * np.pi * (np.asarray(coord_px, dtype=np.float64) + 0.5) / float(period_px)


def coord_of_phase(phase_rad, period_px: float) -> np.ndarray:
    """Projector coordinate of an unwrapped phase (inverse of :func:`phase_of`)."""
    return np.asarray(phase_rad, dtype=np.float64) * float(period_px) / (2.0 * np.pi) - 0.5


def phase_intensity(coord_px, period_px: float, shift_rad: float) -> np.ndarray:
    """``0.5 + 0.5 cos(phi - delta)`` in [0, 1]: the value a phase-shift frame shows at a coordinate."""
    return 0.5 + 0.5 * np.cos(phase_of(coord_px, period_px) - shift_rad)


def wrapped_phase(frames, shifts_rad) -> tuple[np.ndarray, np.ndarray]:
    """N-step phase from (N, ...) intensities: (phase in [0, 2 pi), modulation ``B``), where
    ``I_k = A + B cos(phi - delta_k)``; ``B = 2/N |sum_k I_k exp(i delta_k)|``."""
    i = np.asarray(frames, dtype=np.float64)
    d = np.asarray(shifts_rad, dtype=np.float64).reshape((-1,) + (1,) * (i.ndim - 1))
    s = np.sum(i * np.sin(d), axis=0)
    c = np.sum(i * np.cos(d), axis=0)
    return np.mod(np.arctan2(s, c), 2.0 * np.pi), 2.0 / i.shape[0] * np.hypot(s, c)


def unwrap_temporal(wrapped_rad, periods_px) -> np.ndarray:
    """Coordinate (projector px) from wrapped phases of several periods, coarsest first
    (hierarchical temporal unwrapping, Huntley and Saldner 1993; Zuo et al. 2016, sec. 3.2):
    the coarsest period must cover the axis (its phase is unwrapped already); each finer phase
    takes the period count ``k = round((phase_of(x, p) - phi) / 2 pi)`` from the coordinate ``x``
    of the coarser ones, then ``x = coord_of_phase(phi + 2 pi k, p)``.

    ``wrapped_rad``: (F, ...) wrapped phases in [0, 2 pi); ``periods_px``: (F,) decreasing."""
    phases = np.asarray(wrapped_rad, dtype=np.float64)
    periods = [float(p) for p in periods_px]
    coord = coord_of_phase(phases[0], periods[0])
    for phi, p in zip(phases[1:], periods[1:]):
        k = np.round((phase_of(coord, p) - phi) / (2.0 * np.pi))
        coord = coord_of_phase(phi + 2.0 * np.pi * k, p)
    return coord


def de_bruijn(k: int, n: int) -> np.ndarray:
    """(k**n,) int64 the lexicographically least De Bruijn sequence B(k, n) (FKM algorithm:
    Fredricksen, Kessler and Maiorana; Ruskey, Combinatorial Generation, sec. 7.2): every word of
    length n over k symbols occurs exactly once as a cyclic window."""
    if k < 2 or n < 1:
        raise ValueError(f"De Bruijn needs k >= 2 symbols and order n >= 1, got k={k}, n={n}")
    a = [0] * (k * n)
    seq: list[int] = []

    def db(t: int, p: int) -> None:
        if t > n:
            if n % p == 0:
                seq.extend(a[1:p + 1])
            return
        a[t] = a[t - p]
        db(t + 1, p)
        for j in range(a[t - p] + 1, k):
            a[t] = j
            db(t + 1, t)

    db(1, 1)
    return np.asarray(seq, dtype=np.int64)


#: The stripe colours' alphabet of the De Bruijn pattern: the 3-bit RGB transitions (a stripe's
#: colour is the previous colour XOR a transition, so neighbours always differ; Zhang, Curless and
#: Seitz, 3DPVT 2002, sec. 3). Transition symbol s in 0..k-1 is the RGB bit vector s + 1.
DEBRUIJN_MAX_SYMBOLS = 7


def debruijn_colours(k: int, n: int, n_stripes: int) -> tuple[np.ndarray, np.ndarray]:
    """(symbols (n_stripes,) int64, colours (n_stripes, 3) float64 in {0, 1}) of the first
    ``n_stripes`` stripes: stripe i's colour is the XOR of transitions 0..i (of RGB bits) starting
    from black, so any ``n`` consecutive transitions (the colour pairs of n + 1 stripes) name the
    position uniquely within the first ``k**n - n + 1`` windows."""
    if not 2 <= k <= DEBRUIJN_MAX_SYMBOLS:
        raise ValueError(f"De Bruijn colour stripes take 2..{DEBRUIJN_MAX_SYMBOLS} symbols, got {k}")
    seq = de_bruijn(k, n)
    if n_stripes > seq.size:
        raise ValueError(f"B({k}, {n}) has {seq.size} symbols, fewer than {n_stripes} stripes")
    symbols = seq[:n_stripes]
    codes = np.bitwise_xor.accumulate(symbols + 1)  # 3-bit RGB words, never equal neighbours
    colours = ((codes[:, None] >> np.array([2, 1, 0])) & 1).astype(np.float64)
    return symbols, colours
