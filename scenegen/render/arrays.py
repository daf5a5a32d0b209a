"""numpy data into Dr.Jit arrays at a fixed memory alignment, so that a traced kernel does not
depend on where numpy happened to put its inputs.

In the LLVM back end Dr.Jit maps a contiguous numpy array zero-copy and marks it *unaligned* when
its address is not a multiple of ``min(64, vector width x item size)`` bytes. An unaligned input
changes the kernel: ``align 1`` vector loads instead of ``align 64``, and separate gathers instead
of packet gathers (e.g. of a mesh's UVs). The values computed are the same, but the kernel's hash
is not, so Dr.Jit's on-disk kernel cache misses and the process compiles again. numpy's buffers
(glibc ``malloc``) are only 16-byte aligned, at addresses that vary between identical runs:
measured, the demo's render kernel had 3481 or 3639 operations and the truth kernel 441 or 515
depending on the run. Every numpy array that becomes a Dr.Jit array goes through
:func:`to_jit` (docs/performance.md, "Warm processes").
"""
from __future__ import annotations

import numpy as np

#: Bytes: a cache line, and the most Dr.Jit's LLVM back end asks of an input (AVX-512).
ALIGN = 64


def aligned(a, dtype) -> np.ndarray:
    """A C-contiguous copy of ``a`` cast to ``dtype`` (as ``astype`` casts) whose data starts at
    a multiple of :data:`ALIGN` bytes."""
    src = np.asarray(a)
    dt = np.dtype(dtype)
    nbytes = src.size * dt.itemsize
    buf = np.empty(nbytes + ALIGN, np.uint8)
    start = (-buf.ctypes.data) % ALIGN
    out = buf[start:start + nbytes].view(dt).reshape(src.shape)
    np.copyto(out, src, casting="unsafe")
    return out


def to_jit(cls, a, dtype):
    """``cls(a)`` for a flat Dr.Jit array type ``cls`` (e.g. ``mi.Float``), from an aligned
    copy of ``a`` (raveled, cast to ``dtype``): the same values, an address-independent kernel."""
    return cls(aligned(a, dtype).ravel())
