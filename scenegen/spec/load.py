"""Entry points: a spec file or spec text -> validated :class:`~scenegen.spec.model.SceneSpec`.

The YAML is composed by :mod:`scenegen.located_yaml` (every value keeps its line) and parsed
section by section by :mod:`scenegen.spec.parse`.
"""
from __future__ import annotations

from pathlib import Path

from scenegen.located_yaml import Document
from scenegen.located_yaml.source import read_source
from scenegen.spec.model.scene import SceneSpec
from scenegen.spec.parse.context import derive_seed
from scenegen.spec.parse.scene import TOP_LEVEL_KEYS, parse_document


def load_spec(path) -> SceneSpec:
    """Read and validate a YAML scene spec. Relative file paths in it resolve against its folder."""
    p = Path(path)
    text = read_source(p, "spec file")  # size limit, UTF-8, one-line errors
    return parse_spec(text, file=str(path), base_dir=p.resolve().parent)


def parse_spec(text: str, file: str = "<string>", base_dir=None) -> SceneSpec:
    """Parse and validate spec text. ``base_dir`` (default: the current directory, or the folder
    of ``file`` when it exists) is where relative file paths resolve."""
    if base_dir is None:
        fp = Path(file)
        base_dir = fp.resolve().parent if fp.is_file() else Path.cwd()
    return parse_document(Document(text, file, Path(base_dir)))


__all__ = ["load_spec", "parse_spec", "derive_seed", "TOP_LEVEL_KEYS"]
