"""PNG and EXR files read through their C libraries without the libraries' own messages.

OpenEXR, and libpng inside OpenCV, print their warnings and errors about a malformed file
straight to the process's stderr or stdout (file descriptors 2 and 1: "t.exr:
(EXR_ERR_BAD_CHUNK_LEADER) ...", "Warning: Exception raised reading pixel data ...", "[ WARN:0@0.2]
global grfmt_png.cpp ...", "libpng error: ..."), ahead of recon-eval's one-line error naming the
file and what was expected. recon_eval's readers call the scenegen codecs
through :func:`read_png` and :func:`read_exr` here (or inside :func:`quiet_native_output`),
which point descriptors 1 and 2 at the null device for the length of the call; the file's fault
reaches the user as the reader's error, and an EXR error always names the file.
"""
from __future__ import annotations

import os
import sys
import threading
from contextlib import ExitStack, contextmanager
from pathlib import Path

import numpy as np

from scenegen.dataset import codecs

_LOCK = threading.Lock()  # the descriptors are the process's: one quiet call at a time


@contextmanager
def quiet_native_output():
    """Descriptors 1 and 2 on the null device inside the block (OpenEXR's Python binding prints
    its "Warning: Exception raised reading pixel data" to stdout); Python's sys.stdout and
    sys.stderr are flushed first and work again after it."""
    with _LOCK, ExitStack() as stack:
        for stream, fd in ((sys.stdout, 1), (sys.stderr, 2)):
            stream.flush()
            stack.enter_context(_on_null_device(fd))
        yield


@contextmanager
def _on_null_device(fd: int):
    try:
        saved = os.dup(fd)
    except OSError:  # no such descriptor: nothing to protect
        yield
        return
    try:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, fd)
        os.close(null)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


def read_png(path) -> np.ndarray:
    """:func:`scenegen.dataset.codecs.read_png`, quietly (ValueError for a file OpenCV cannot decode)."""
    with quiet_native_output():
        return codecs.read_png(path)


def read_exr(path) -> dict[str, np.ndarray]:
    """:func:`scenegen.dataset.codecs.read_exr`, quietly; ValueError ``<path>: not a readable EXR
    file (<why>)`` whatever part of the read failed."""
    p = Path(path)
    try:
        with quiet_native_output():
            return codecs.read_exr(p)
    except ValueError as exc:
        why = str(exc).removeprefix(f"{p}: ")
        if not why.startswith("not a readable EXR file"):
            why = f"not a readable EXR file ({why})"
        raise ValueError(f"{p}: {why}") from None
