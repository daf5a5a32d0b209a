"""Decoding without the libraries' own messages: the one place that silences them.

OpenCV logs ``[ WARN:0@...]`` / ``[ERROR:0@...]`` lines (libpng's complaints, ``imdecode_``)
and OpenEXR prints ``Warning: ...`` on stdout and ``(EXR_ERR_...)`` lines on stderr when a file
is bad; every decode whose failure we report ourselves (one line naming the file) goes through
:func:`quiet_native_output`, so those lines never come before our error. For the call only,
under a lock: the process's file descriptors 1 and 2 point at /dev/null (the C libraries write
there), ``sys.stdout``/``sys.stderr`` at a discarded buffer (the bindings also print through
Python), and OpenCV's log level is silent; all three are restored after, also on an error.
"""
from __future__ import annotations

import io
import os
import sys
import threading
from contextlib import contextmanager, redirect_stderr, redirect_stdout

import cv2
import numpy as np

_LOCK = threading.RLock()


@contextmanager
def quiet_native_output():
    """Run the body with OpenCV's logging silent and fds 1 and 2 sent to /dev/null (restored after,
    also on an exception)."""
    with _LOCK:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()  # nothing Python already printed is lost to the redirect
            except (OSError, ValueError):
                pass
        level = cv2.utils.logging.getLogLevel()
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)
        saved = []
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            try:
                for fd in (1, 2):
                    try:
                        saved.append((fd, os.dup(fd)))
                        os.dup2(null, fd)
                    except OSError:  # no such descriptor (a daemon): nothing to silence there
                        pass
            finally:
                os.close(null)
            with redirect_stdout(io.StringIO()), redirect_stderr(io.StringIO()):  # bindings print via Python too
                yield
        finally:
            for fd, copy in saved:
                os.dup2(copy, fd)
                os.close(copy)
            cv2.utils.logging.setLogLevel(level)


def decode_image(data: bytes, flags: int = cv2.IMREAD_UNCHANGED) -> np.ndarray | None:
    """``cv2.imdecode`` of encoded image bytes (PNG, JPEG, BMP, Radiance HDR, ...) without
    OpenCV's log lines; None when OpenCV cannot decode them. ``cv2.error`` (e.g. a header
    announcing more pixels than OpenCV allows) becomes a ValueError with OpenCV's last line."""
    with quiet_native_output():
        try:
            img = cv2.imdecode(np.frombuffer(bytes(data), np.uint8), flags)
        except cv2.error as e:
            raise ValueError(f"OpenCV could not decode it ({str(e).strip().splitlines()[-1]})") from None
    return None if img is None or img.size == 0 else img
