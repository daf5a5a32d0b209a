"""Package faces whose names load on first use (PEP 562), so that importing one light module of
the dataset (a stream's schema, the truth kinds) does not load every codec's library (OpenEXR,
OpenCV): `scenegen validate` reads a spec, whose sensor kinds name their truth and streams,
without them.
"""
from __future__ import annotations

import importlib
import sys
import types
from typing import Callable


def lazy_exports(package: str, exports: dict[str, tuple[str, ...]]) -> tuple[Callable[[str], object], list[str]]:
    """(``__getattr__``, ``__all__``) for ``package`` exporting ``exports`` {submodule: names}:
    a name's submodule is imported when the name is first read (then cached in the package)."""
    where = {name: sub for sub, names in exports.items() for name in names}

    def __getattr__(name: str):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{where[name]}"), name)
        setattr(importlib.import_module(package), name, value)
        return value

    sys.modules[package].__class__ = _face(where)
    return __getattr__, list(where)


def _face(where: dict[str, str]) -> type:
    """A package module class in which importing a submodule does not shadow the exported name of
    the same name (``scenegen.dataset.verify``: the function, as an eager ``from .verify import
    verify`` would leave it)."""
    class Face(types.ModuleType):
        def __setattr__(self, name, value):
            if name in where and isinstance(value, types.ModuleType):
                return
            super().__setattr__(name, value)
    return Face
