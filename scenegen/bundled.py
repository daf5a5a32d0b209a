"""The examples that ship with the package: ``scenes/``, ``gates/``, ``examples/`` (your own
estimator: ``my_fmatrix.py``, its methods file and gates) and ``baselines/`` of the repository,
installed as package data under ``scenegen/examples/`` (in a checkout those are links to the
repository's folders), found with :mod:`importlib.resources` (``scenegen examples``), so a pip
user's ``scenegen examples --copy .`` holds every file docs/ci.md's worked example names."""
from __future__ import annotations

import shutil
from importlib import resources
from pathlib import Path

#: The bundled folders, as named in the repository and in a copy.
FOLDERS = ("scenes", "gates", "examples", "baselines")


def examples_root():
    """The installed ``scenegen/examples`` folder (a Traversable)."""
    return resources.files("scenegen") / "examples"


def example_files() -> list[tuple[str, str]]:
    """(folder, path) of every bundled file, sorted per folder: ``("scenes", ".../demo.yaml")``, ..."""
    out = []
    for folder in FOLDERS:
        base = Path(str(examples_root() / folder))
        out += [(folder, str(p)) for p in sorted(base.rglob("*")) if p.is_file() and "__pycache__" not in p.parts]
    return out


def copy_examples(dest) -> int:
    """Copy the bundled folders (``scenes/``, ``gates/``, ``examples/``, ``baselines/``) into
    ``dest`` (which must not hold them yet); the number of files copied."""
    dest = Path(dest)
    for folder in FOLDERS:
        if (dest / folder).exists():
            raise ValueError(f"{dest / folder} exists; choose another destination")
    n = 0
    for folder in FOLDERS:
        src = Path(str(examples_root() / folder))
        shutil.copytree(src, dest / folder, ignore=shutil.ignore_patterns("__pycache__"))
        n += sum(1 for p in (dest / folder).rglob("*") if p.is_file())
    return n
