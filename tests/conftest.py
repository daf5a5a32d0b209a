"""Session-wide test settings: with ``-m "not render"`` Mitsuba and Dr.Jit cannot be imported,
so a test that needs them but lacks the ``render`` marker fails instead of slowing the fast loop.

Under pytest-xdist (``make test`` runs ``-n 2``) each worker process renders on its share of the
cores (Dr.Jit's default is a pool of one thread per core in every process: two workers would run
twice as many render threads as there are cores)."""
from __future__ import annotations

import importlib.abc
import os
import sys

import pytest

_BLOCKED = ("mitsuba", "drjit")


class _NoMitsuba(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in _BLOCKED:
            raise ImportError(f"{name} imported by a test without the 'render' marker (run with -m 'not render')")
        return None


def pytest_configure(config):
    markexpr = config.getoption("markexpr") or ""
    if "not render" in markexpr and not any(m in sys.modules for m in _BLOCKED):
        sys.meta_path.insert(0, _NoMitsuba())


def _worker_render_threads() -> int | None:
    """This xdist worker's share of the cores; None outside xdist."""
    workers = os.environ.get("PYTEST_XDIST_WORKER_COUNT")
    return max(1, (os.cpu_count() or 1) // int(workers)) if workers else None


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    share = _worker_render_threads()
    if share is not None and item.get_closest_marker("render") is not None:
        from scenegen.render.threads import render_threads, set_render_threads

        if render_threads() != share:  # first render test here, or a test changed it
            set_render_threads(share)
