"""Dr.Jit's thread pool size in this process: several renderers sharing one machine's cores
(a local Dask cluster's workers) each take their share instead of a pool of all cores."""
from __future__ import annotations

import sys

from scenegen.render.backend import configure_llvm


def set_render_threads(n: int) -> None:
    """Run this process's Dr.Jit kernels on ``n`` >= 1 threads (the default: one per core)."""
    if int(n) < 1:
        raise ValueError(f"render threads must be at least 1, got {n}")
    configure_llvm()
    import drjit as dr  # only now: DRJIT_LIBLLVM_PATH must be set before Dr.Jit loads
    dr.set_thread_count(int(n))


def render_threads() -> int | None:
    """This process's Dr.Jit thread count; None before Dr.Jit is loaded."""
    if "drjit" not in sys.modules:
        return None
    import drjit as dr  # already loaded (checked above): no import cost, no libLLVM choice
    return int(dr.thread_count())
