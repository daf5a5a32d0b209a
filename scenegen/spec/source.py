"""What a worker process needs to rebuild a spec (or one of its variants) exactly."""
from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path

from scenegen.located_yaml.source import read_source
from scenegen.spec.load import parse_spec
from scenegen.spec.model.scene import SceneSpec
from scenegen.spec.variants import derive_variant

__all__ = ["SpecSource"]


@dataclass(frozen=True)
class SpecSource:
    """What a worker process needs to rebuild a spec exactly: the YAML text, the file name its
    errors name, the folder relative paths resolve against, and the variant index (None = the
    spec as written). Picklable, unlike the SceneSpec (read-only mappings)."""

    text: str
    file: str
    base_dir: str
    variant_index: int | None = None

    @classmethod
    def from_path(cls, path, variant_index: int | None = None) -> "SpecSource":
        p = Path(path)
        text = read_source(p, "spec file")  # size limit, UTF-8, one-line errors
        return cls(text, str(path), str(p.resolve().parent), variant_index)

    @property
    def key(self) -> str:
        """A hash identifying the spec and variant (a worker's scene cache key)."""
        h = hashlib.sha256("\0".join((self.text, self.file, self.base_dir, str(self.variant_index))).encode())
        return h.hexdigest()

    def load(self) -> SceneSpec:
        spec = parse_spec(self.text, file=self.file, base_dir=self.base_dir)
        return spec if self.variant_index is None else derive_variant(spec, self.variant_index)
