"""Session-wide test settings: with ``-m "not render"`` Mitsuba and Dr.Jit cannot be imported,
so a test that needs them but lacks the ``render`` marker fails instead of slowing the fast loop."""
from __future__ import annotations

import importlib.abc
import sys

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
