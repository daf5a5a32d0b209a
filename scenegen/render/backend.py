"""Pick a Mitsuba variant and a libLLVM that works, before Dr.Jit is imported.

Dr.Jit's LLVM back end JIT-compiles through a system libLLVM found at run time. Debian's
libLLVM 15 aborts the whole process on the first kernel using min/max (``Cannot select ...
fminimum``, uncatchable) and 14 leaves the back end inactive, so only 16 or newer is used, chosen
here explicitly through ``DRJIT_LIBLLVM_PATH`` (see docs/conventions.md and shared notes).
Without one, ``auto`` falls back to ``scalar_rgb`` with a warning.
"""
from __future__ import annotations

import contextlib
import glob
import os
import re
import sys
import warnings

from scenegen.spec.model import RENDER_VARIANTS as VARIANTS  # the spec's `variant:` values

MIN_LLVM_MAJOR = 16
_SEARCH = (
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.*", "/usr/lib/x86_64-linux-gnu/libLLVM-*.so*",
    "/usr/lib/aarch64-linux-gnu/libLLVM.so.*", "/usr/lib/aarch64-linux-gnu/libLLVM-*.so*",
    "/usr/lib/llvm-*/lib/libLLVM*.so*", "/usr/local/lib/libLLVM*.so*", "/opt/homebrew/opt/llvm/lib/libLLVM.dylib",
)


class BackendError(RuntimeError):
    """The requested variant cannot run on this machine."""


def llvm_major(path: str) -> int | None:
    """The LLVM major version of a libLLVM file, from the names Debian, Ubuntu and apt.llvm.org
    use (``libLLVM-16.so.1``, ``libLLVM.so.19.1``, ``libLLVM-17.so``); where the file name says
    none (``libLLVM.so.1``), its ``llvm-N`` folder (``/usr/lib/llvm-20/lib``). None: unknown."""
    m = re.search(r"libLLVM[-.]?(?:so\.)?(\d+)", os.path.basename(path))
    if m and int(m.group(1)) >= 4:  # an soname counter such as .so.1 is no LLVM version
        return int(m.group(1))
    d = re.search(r"(?:^|/)llvm-(\d+)(?:/|$)", os.path.dirname(path))
    return int(d.group(1)) if d else None


def find_libllvm(patterns=_SEARCH) -> str | None:
    """The newest libLLVM >= 16 on this machine (files matching the glob ``patterns``), or None."""
    found = []
    for pattern in patterns:
        for path in glob.glob(pattern):
            major = llvm_major(path)
            if major is not None and major >= MIN_LLVM_MAJOR and os.path.isfile(path):
                found.append((major, path))
    return max(found)[1] if found else None


def configure_llvm() -> bool:
    """Point Dr.Jit at a good libLLVM if it has not been imported yet. True if one is set."""
    current = os.environ.get("DRJIT_LIBLLVM_PATH")
    if current and (llvm_major(current) or MIN_LLVM_MAJOR) >= MIN_LLVM_MAJOR and os.path.isfile(current):
        return True
    if "drjit" in sys.modules:
        return current is not None
    path = find_libllvm()
    if path is None:
        return False
    os.environ["DRJIT_LIBLLVM_PATH"] = path
    return True


def llvm_available() -> bool:
    """True if Dr.Jit's LLVM back end runs with a libLLVM >= 16."""
    if not configure_llvm():
        return False
    import drjit as dr  # only now: DRJIT_LIBLLVM_PATH must be set before Dr.Jit loads

    try:
        return dr.has_backend(dr.JitBackend.LLVM) and dr.detail.llvm_version()[0] >= MIN_LLVM_MAJOR
    except Exception:  # an inactive back end raises on query
        return False


def cuda_available() -> bool:
    configure_llvm()
    import drjit as dr  # only now: DRJIT_LIBLLVM_PATH must be set before Dr.Jit loads

    try:
        return bool(dr.has_backend(dr.JitBackend.CUDA))
    except Exception:
        return False


def resolve_variant(requested: str = "auto") -> str:
    """The variant to run: ``auto`` takes cuda_ad_rgb, then llvm_ad_rgb, then scalar_rgb."""
    if requested not in VARIANTS:
        raise BackendError(f"variant must be one of {VARIANTS}, got {requested!r}")
    if requested == "auto":
        if cuda_available():
            return "cuda_ad_rgb"
        if llvm_available():
            return "llvm_ad_rgb"
        warnings.warn(
            "no working libLLVM >= 16 found (install one of Debian's/Ubuntu's libllvm16..21, e.g. 'make llvm', "
            "or set DRJIT_LIBLLVM_PATH); "
            "falling back to scalar_rgb, which is 40-60x slower", RuntimeWarning, stacklevel=2)
        return "scalar_rgb"
    if requested == "llvm_ad_rgb" and not llvm_available():
        raise BackendError("llvm_ad_rgb needs libLLVM >= 16 (Debian/Ubuntu: apt-get install libllvm19, or 16..21; or set "
                           "DRJIT_LIBLLVM_PATH); libLLVM 15 aborts the process and is never used")
    if requested == "cuda_ad_rgb" and not cuda_available():
        raise BackendError("cuda_ad_rgb needs an NVIDIA GPU with a working CUDA driver")
    return requested


#: Mitsuba's own log lines (warnings and errors): shown on stderr in our words (``scenegen:
#: Mitsuba warning: [Plugin] message``, without its timestamp and colour codes), or, with
#: ``show`` off (the CLI's -q), warnings dropped and errors still shown.
RENDERER_LOG = {"show": True, "appender": None}
_MITSUBA_PREFIX = re.compile(r"^\S+ \S+ +(?:WARN|ERROR|INFO|DEBUG|TRACE)\s+")


def set_renderer_log(show: bool) -> None:
    RENDERER_LOG["show"] = bool(show)


@contextlib.contextmanager
def renderer_log(show: bool):
    """Mitsuba's warnings shown or not inside the block (restored after it)."""
    before = RENDERER_LOG["show"]
    set_renderer_log(show)
    try:
        yield
    finally:
        set_renderer_log(before)


def renderer_log_line(level_name: str, text: str) -> str:
    """Our wording of one Mitsuba log line."""
    return f"scenegen: Mitsuba {level_name}: {_MITSUBA_PREFIX.sub('', text.strip())}"


def _install_log(mi) -> None:
    if RENDERER_LOG["appender"] is not None:
        return

    class Appender(mi.Appender):
        def append(self, level, text):
            error = level == mi.LogLevel.Error
            if error or RENDERER_LOG["show"]:
                print(renderer_log_line("error" if error else "warning", text), file=sys.stderr, flush=True)

        def log_progress(self, *args):
            pass

    logger = mi.logger() if hasattr(mi, "logger") else mi.Thread.thread().logger()
    appender = Appender()
    logger.clear_appenders()
    logger.add_appender(appender)
    RENDERER_LOG["appender"] = appender  # kept alive here


def load_mitsuba(variant: str = "auto"):
    """Import Mitsuba with a safe libLLVM and the resolved variant set, its log lines in our
    words (:data:`RENDERER_LOG`); returns the module."""
    resolved = resolve_variant(variant)
    import mitsuba as mi  # only now: after the libLLVM is chosen and the variant resolved

    mi.set_variant(resolved)
    _install_log(mi)
    return mi
