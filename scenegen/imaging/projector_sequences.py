"""The pattern sequences a projector of the spec shows, by name (:data:`SEQUENCES`), built by
:mod:`scenegen.imaging.patterns` (the codes' rules: :mod:`scenegen.geometry.sl_codes`), and how
each frame is described in a dataset's ``patterns/<view>/sequence.json`` (:func:`frame_entry`).

A builder takes the projector's size and :class:`SequenceOptions` and returns a
:class:`scenegen.imaging.patterns.PatternSequence` (values in [0, 1], (N, H, W) or (N, H, W, 3));
the projector's radiometry (:mod:`scenegen.spec.sensors.projector`) turns a value into light.
``white`` is one all-white frame (the radiometry's reference).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from scenegen.imaging import patterns
from scenegen.imaging.patterns import FrameCode, PatternSequence

#: The spec's coded axes -> the patterns' axes (u: columns, v: rows).
AXES = {"columns": ("u",), "rows": ("v",), "both": ("u", "v")}
AXIS_NAMES = {"u": "columns", "v": "rows", "": ""}


@dataclass(frozen=True, kw_only=True)
class SequenceOptions:
    """What a sequence is made with (the projector's spec values; each builder reads its own)."""

    axes: str = "both"  # a key of AXES (De Bruijn stripes: the first of them)
    inverses: bool = True  # gray / binary: each bit frame followed by its inverse
    references: bool = True  # gray / binary: an all-white and an all-black frame first
    phase_steps: int = 4
    phase_periods_px: tuple[float, ...] | None = None  # None: patterns.default_periods_px
    stripe_px: int = 4
    dots_seed: int = 0
    dots_density: float = 0.1
    dot_px: int = 1


def _white(width: int, height: int, o: SequenceOptions) -> PatternSequence:
    return PatternSequence(name="white", width=width, height=height, images=np.ones((1, height, width), np.float32),
                           frames=(FrameCode(kind="white"),))


#: Sequence name -> builder(width, height, SequenceOptions) -> PatternSequence.
SEQUENCES: dict[str, Callable[[int, int, SequenceOptions], PatternSequence]] = {
    "gray": lambda w, h, o: patterns.gray_code(w, h, axes=AXES[o.axes], inverses=o.inverses, references=o.references),
    "binary": lambda w, h, o: patterns.binary_code(w, h, axes=AXES[o.axes], inverses=o.inverses,
                                                   references=o.references),
    "phase_shift": lambda w, h, o: patterns.phase_shift(w, h, n_steps=o.phase_steps, periods_px=o.phase_periods_px,
                                                        axes=AXES[o.axes]),
    "debruijn": lambda w, h, o: patterns.debruijn_stripes(w, h, stripe_px=o.stripe_px, axis=AXES[o.axes][0]),
    "dots": lambda w, h, o: patterns.random_dots(w, h, seed=o.dots_seed, density=o.dots_density, dot_px=o.dot_px),
    "white": _white,
}


def frame_name(f: FrameCode) -> str:
    """A readable name of a frame: ``white``, ``black``, ``u_bit07`` (bit counted from the least
    significant), ``u_bit07_inv``, ``u_phase_p256.0_s2``, ``debruijn_u``, ``dots``."""
    if f.kind in ("gray", "binary"):
        return f"{f.axis}_bit{f.n_bits - 1 - f.bit:02d}" + ("_inv" if f.inverse else "")
    if f.kind == "phase":
        return f"{f.axis}_phase_p{f.period_px:g}_s{f.step}"
    if f.kind == "debruijn":
        return f"debruijn_{f.axis}"
    return f.kind


def frame_entry(f: FrameCode) -> dict:
    """A frame as ``sequence.json`` describes it: ``name``, ``kind``, ``axis`` (``columns`` /
    ``rows`` / ``""``), ``bit`` (the code word's bit shown, 0 = least significant; -1 if none),
    ``n_bits``, ``inverse``, and a phase frame's ``period_px``, ``step``, ``n_steps``,
    ``shift_rad``, a De Bruijn frame's ``stripe_px``, ``symbols``, ``order``, a dot frame's
    ``seed``, ``density``, ``dot_px``."""
    d = {"name": frame_name(f), "kind": f.kind, "axis": AXIS_NAMES[f.axis],
         "bit": f.n_bits - 1 - f.bit if f.kind in ("gray", "binary") else -1, "n_bits": f.n_bits,
         "inverse": f.inverse}
    if f.kind == "phase":
        d.update(period_px=f.period_px, step=f.step, n_steps=f.n_steps, shift_rad=f.shift_rad)
    elif f.kind == "debruijn":
        d.update(stripe_px=f.stripe_px, symbols=f.symbols, order=f.order)
    elif f.kind == "dots":
        d.update(seed=f.seed, density=f.density, dot_px=f.dot_px)
    return d
