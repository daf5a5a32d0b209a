"""Structured-light pattern sequences for a projector of ``width`` x ``height`` pixels (numpy).

Each generator returns a :class:`PatternSequence`: its images, float32 in [0, 1] (``(N, H, W)``
grey or ``(N, H, W, 3)`` RGB; display values, before the projector's response), and a
:class:`FrameCode` per frame saying what the frame encodes. The codes' rules (pixel index of a
continuous coordinate, bit order, Gray code, phase, De Bruijn) are stated once in
:mod:`scenegen.geometry.sl_codes`, which decoders import too.

* :func:`gray_code`, :func:`binary_code`: all-white and all-black reference frames, then per axis
  (``u`` columns, ``v`` rows) one frame per bit, most significant first, each followed by its
  inverse (Inokuchi et al. 1984; Lanman and Taubin, "Build Your Own 3D Scanner", 2009, sec. 5.2).
* :func:`phase_shift`: N-step sinusoids at several periods, coarsest first (temporal unwrapping).
* :func:`debruijn_stripes`: one RGB frame of colour stripes from a De Bruijn sequence of
  transitions (Zhang, Curless and Seitz 2002).
* :func:`random_dots`: one seeded binary dot frame (the IR speckle of active stereo cameras).

:func:`sample` gives what a sequence shows at continuous projector coordinates (the pixel that
covers them), :func:`perfect_code` the code a perfect decoder reads there.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry.sl_codes import (OUTSIDE, binary_to_gray, bits_for, code_bits, debruijn_colours,
                                        gray_to_binary, phase_intensity, phase_shifts_rad, pixel_index)

__all__ = ["FrameCode", "PatternSequence", "gray_code", "binary_code", "phase_shift", "debruijn_stripes",
           "random_dots", "sample", "perfect_code", "gray_to_binary", "binary_to_gray", "AXES"]

#: The projector axes a frame can code: ``u`` (columns, a code per column) and ``v`` (rows).
AXES = ("u", "v")
#: Frame kinds, what each shows.
FRAME_KINDS = ("white", "black", "gray", "binary", "phase", "debruijn", "dots")


@dataclass(frozen=True, kw_only=True)
class FrameCode:
    """What one frame encodes. Fields not used by a ``kind`` keep their defaults."""
    kind: str  # one of FRAME_KINDS
    axis: str = ""  # "u" or "v" for coding frames; "" for references and dots
    bit: int = -1  # gray / binary: bit shown, 0 = most significant of n_bits
    n_bits: int = 0  # gray / binary: bits of the axis' code words
    inverse: bool = False  # gray / binary: the complement of the bit frame
    period_px: float = 0.0  # phase: sinusoid period, projector pixels
    step: int = -1  # phase: k of N steps
    n_steps: int = 0  # phase: N
    shift_rad: float = 0.0  # phase: delta_k = 2 pi k / N
    stripe_px: int = 0  # debruijn: stripe width, projector pixels
    symbols: int = 0  # debruijn: alphabet size k of B(k, n)
    order: int = 0  # debruijn: window length n of B(k, n)
    seed: int = -1  # dots: the numpy seed
    density: float = 0.0  # dots: fraction of lit dot cells
    dot_px: int = 0  # dots: dot cell size, projector pixels


@dataclass(frozen=True, kw_only=True, eq=False)
class PatternSequence:
    """A projector pattern sequence: ``images[i]`` shows ``frames[i]``."""
    name: str  # "gray", "binary", "phase_shift", "debruijn", "dots"
    width: int  # projector width, pixels
    height: int  # projector height, pixels
    images: np.ndarray  # (N, H, W) or (N, H, W, 3) float32 in [0, 1]
    frames: tuple[FrameCode, ...]

    def __post_init__(self):
        self.images.setflags(write=False)

    @property
    def axes(self) -> tuple[str, ...]:
        """The axes the sequence codes, in frame order."""
        return tuple(dict.fromkeys(f.axis for f in self.frames if f.axis))


def _check_size(width: int, height: int) -> None:
    if int(width) != width or int(height) != height or width < 1 or height < 1:
        raise ValueError(f"projector size must be positive integers, got {width} x {height}")


def _check_axes(axes) -> tuple[str, ...]:
    axes = tuple(axes)
    if not axes or any(a not in AXES for a in axes) or len(set(axes)) != len(axes):
        raise ValueError(f"axes must be distinct values of {AXES}, got {axes}")
    return axes


def _length(axis: str, width: int, height: int) -> int:
    return width if axis == "u" else height


def _bit_code(kind: str, width: int, height: int, axes, inverses: bool, references: bool) -> PatternSequence:
    _check_size(width, height)
    axes = _check_axes(axes)
    frames: list[FrameCode] = []
    if references:
        frames += [FrameCode(kind="white"), FrameCode(kind="black")]
    for axis in axes:
        n = bits_for(_length(axis, width, height))
        for b in range(n):
            frames.append(FrameCode(kind=kind, axis=axis, bit=b, n_bits=n))
            if inverses:
                frames.append(FrameCode(kind=kind, axis=axis, bit=b, n_bits=n, inverse=True))
    return _build(kind, width, height, frames)


def gray_code(width: int, height: int, *, axes=AXES, inverses: bool = True,
              references: bool = True) -> PatternSequence:
    """Gray-code stripes: [white, black,] then per axis ``bits_for(length)`` bit frames, MSB
    first, each followed by its inverse. Column ``c`` is white in bit frame ``b`` when bit
    ``n - 1 - b`` of ``binary_to_gray(c)`` is 1."""
    return _bit_code("gray", width, height, axes, inverses, references)


def binary_code(width: int, height: int, *, axes=AXES, inverses: bool = True,
                references: bool = True) -> PatternSequence:
    """Plain binary stripes, the same frames as :func:`gray_code` with code word ``c``."""
    return _bit_code("binary", width, height, axes, inverses, references)


def default_periods_px(length_px: int, ratio: int = 8, min_period_px: float = 8.0) -> tuple[float, ...]:
    """Coarsest period = the axis length (one period covers it: unique phase), then each ``ratio``
    times finer while it stays >= ``min_period_px``."""
    periods = [float(length_px)]
    while periods[-1] / ratio >= min_period_px:
        periods.append(periods[-1] / ratio)
    return tuple(periods)


def phase_shift(width: int, height: int, *, n_steps: int = 4, periods_px=None,
                axes=("u",)) -> PatternSequence:
    """N-step phase shifting: per axis, per period (coarsest first; the coarsest must be >= the
    axis length for temporal unwrapping), N frames ``0.5 + 0.5 cos(2 pi (c + 0.5) / p - 2 pi k / N)``.
    ``periods_px`` None: :func:`default_periods_px` of each axis."""
    _check_size(width, height)
    axes = _check_axes(axes)
    shifts = phase_shifts_rad(n_steps)
    frames: list[FrameCode] = []
    for axis in axes:
        length = _length(axis, width, height)
        periods = default_periods_px(length) if periods_px is None else tuple(float(p) for p in periods_px)
        if not periods or any(not np.isfinite(p) or p <= 0 for p in periods):
            raise ValueError(f"periods_px must be positive, got {periods}")
        if periods[0] < length:
            raise ValueError(f"the coarsest period {periods[0]} px is shorter than the {axis} axis "
                             f"({length} px): its phase would not be unique")
        for p in periods:
            frames += [FrameCode(kind="phase", axis=axis, period_px=p, step=k, n_steps=n_steps,
                                 shift_rad=float(shifts[k])) for k in range(n_steps)]
    return _build("phase_shift", width, height, frames)


def debruijn_stripes(width: int, height: int, *, stripe_px: int = 4, symbols: int = 5,
                     order: int | None = None, axis: str = "u") -> PatternSequence:
    """One RGB frame of stripes ``stripe_px`` wide along ``axis``: stripe ``i`` (pixels
    ``[i s, (i + 1) s)``) has the colour of :func:`scenegen.geometry.sl_codes.debruijn_colours`.
    ``order`` None: the smallest n whose ``symbols**n - n + 1`` windows cover the stripes."""
    _check_size(width, height)
    _check_axes((axis,))
    if stripe_px < 1:
        raise ValueError(f"stripe_px must be >= 1, got {stripe_px}")
    n_stripes = -(-_length(axis, width, height) // stripe_px)
    if order is None:
        order = 1
        while symbols ** order - order + 1 < n_stripes:
            order += 1
    frame = FrameCode(kind="debruijn", axis=axis, stripe_px=stripe_px, symbols=symbols, order=order)
    return _build("debruijn", width, height, [frame])


def random_dots(width: int, height: int, *, seed: int, density: float = 0.1, dot_px: int = 1) -> PatternSequence:
    """One grey frame of square dots ``dot_px`` wide on a grid of cells, each lit with probability
    ``density`` (``numpy.random.default_rng(seed)``, one uniform per cell in row-major order)."""
    _check_size(width, height)
    if not 0.0 < density <= 1.0 or dot_px < 1:
        raise ValueError(f"dots need 0 < density <= 1 and dot_px >= 1, got {density}, {dot_px}")
    frame = FrameCode(kind="dots", seed=int(seed), density=float(density), dot_px=int(dot_px))
    return _build("dots", width, height, [frame])


def _dots_mask(frame: FrameCode, width: int, height: int) -> np.ndarray:
    s = frame.dot_px
    cells = np.random.default_rng(frame.seed).random((-(-height // s), -(-width // s))) < frame.density
    return np.repeat(np.repeat(cells, s, axis=0), s, axis=1)[:height, :width]


def frame_values(frame: FrameCode, col, row, width: int, height: int) -> np.ndarray:
    """Values (float64, shape of ``col``; RGB frames (..., 3)) of ``frame`` at projector pixel
    indices ``col``, ``row`` (int arrays of one shape, inside the image): the one definition of
    every pattern, used for the images and for :func:`sample`."""
    col = np.asarray(col, dtype=np.int64)
    row = np.asarray(row, dtype=np.int64)
    coord = col if frame.axis == "u" else row
    if frame.kind in ("white", "black"):
        return np.full(col.shape, 1.0 if frame.kind == "white" else 0.0)
    if frame.kind in ("gray", "binary"):
        word = binary_to_gray(coord) if frame.kind == "gray" else coord
        bit = code_bits(word, frame.n_bits)[frame.bit].astype(np.float64)
        return 1.0 - bit if frame.inverse else bit
    if frame.kind == "phase":
        return phase_intensity(coord, frame.period_px, frame.shift_rad)
    if frame.kind == "debruijn":
        n_stripes = -(-_length(frame.axis, width, height) // frame.stripe_px)
        _, colours = debruijn_colours(frame.symbols, frame.order, n_stripes)
        return colours[coord // frame.stripe_px]
    if frame.kind == "dots":
        return _dots_mask(frame, width, height)[row, col].astype(np.float64)
    raise ValueError(f"unknown frame kind {frame.kind!r}; expected one of {FRAME_KINDS}")


def _build(name: str, width: int, height: int, frames: list[FrameCode]) -> PatternSequence:
    row, col = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
    images = np.stack([frame_values(f, col, row, width, height) for f in frames]).astype(np.float32)
    return PatternSequence(name=name, width=width, height=height, images=images, frames=tuple(frames))


def sample(sequence: PatternSequence, uv_px) -> np.ndarray:
    """(N, ...) float32 (RGB: (N, ..., 3)) what each frame shows at continuous projector
    coordinates ``uv_px`` (..., 2): the value of the projector pixel covering them, 0 (no light)
    outside the projector image or at NaN."""
    uv = np.asarray(uv_px, dtype=np.float64)
    col = pixel_index(uv[..., 0], sequence.width)
    row = pixel_index(uv[..., 1], sequence.height)
    inside = (col != OUTSIDE) & (row != OUTSIDE)
    vals = sequence.images[:, np.where(inside, row, 0), np.where(inside, col, 0)]
    mask = inside[None, ..., None] if vals.ndim == inside.ndim + 2 else inside[None]
    return np.where(mask, vals, np.float32(0.0))


def perfect_code(sequence: PatternSequence, uv_px) -> np.ndarray:
    """(..., 2) int64 the code a perfect decoder reads at continuous projector coordinates
    ``uv_px`` (..., 2): per axis (u, v) the projector pixel index (gray, binary, phase_shift; a
    phase decoder reads that pixel's centre, the same integer) or the stripe index (debruijn);
    ``OUTSIDE`` (-1) outside the projector image and for an axis the sequence does not code.
    Random dots code no coordinate: ValueError."""
    if sequence.name == "dots":
        raise ValueError("a random dot pattern codes no projector coordinate (it is matched by correlation)")
    uv = np.asarray(uv_px, dtype=np.float64)
    col = pixel_index(uv[..., 0], sequence.width)
    row = pixel_index(uv[..., 1], sequence.height)
    inside = (col != OUTSIDE) & (row != OUTSIDE)
    out = np.full(uv.shape[:-1] + (2,), OUTSIDE, dtype=np.int64)
    for i, (axis, idx) in enumerate((("u", col), ("v", row))):
        if axis in sequence.axes:
            code = idx // sequence.frames[0].stripe_px if sequence.name == "debruijn" else idx
            out[..., i] = np.where(inside, code, OUTSIDE)
    return out
