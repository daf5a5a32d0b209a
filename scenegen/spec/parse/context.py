"""What a section parser may know about the sections parsed before it.

The top-level parser (:mod:`.scene`) builds one immutable :class:`ParseContext` step by step
(``ctx.but(cameras=...)``) and passes it down; no parser keeps state between calls. Warnings are
the one thing collected: into the context's list, which the top level turns into
``SceneSpec.warnings``.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Mapping

from scenegen.errors import SpecError
from scenegen.geometry import seeds
from scenegen.located_yaml import Document, Node
from scenegen.spec.model.cameras import CameraSpec, Rig
from scenegen.spec.model.geometry import SceneObject
from scenegen.spec.model.lights import Light
from scenegen.spec.model.materials import Material
from scenegen.spec.model.meta import frozen_mapping
from scenegen.spec.model.render import RenderSettings


def derive_seed(scene_seed: int, field_path: str) -> int:
    """Default seed of a seeded thing: stable, differs between field paths (0 .. 2**32 - 1)."""
    return seeds.seed32(scene_seed, field_path)


@dataclass(frozen=True)
class ParseContext:
    doc: Document
    warnings: list[str] = field(default_factory=list)  # 'file:line: field: message', in order
    scene_seed: int | None = None  # the top-level seed (set first)
    render: RenderSettings | None = None  # set after `render:`
    materials: Mapping[str, Material] = field(default_factory=frozen_mapping)
    cameras: Mapping[str, CameraSpec] = field(default_factory=frozen_mapping)
    sensors: Mapping[str, Mapping] = field(default_factory=frozen_mapping)  # other sensor kinds' sections
    rigs: Mapping[str, Rig] = field(default_factory=frozen_mapping)
    objects: tuple[SceneObject, ...] = ()
    lights: tuple[Light, ...] = ()
    sequence: object = None  # scenegen.spec.model.timeline.SequenceSpec, set after `sequence:`

    def but(self, **changes) -> "ParseContext":
        """A copy with some sections known (the warnings list is shared)."""
        return dataclasses.replace(self, **changes)

    def warn(self, node: Node, message: str) -> None:
        self.warnings.append(str(SpecError.at(node.where, message)))

    def seed_for(self, path: str) -> int:
        """The default seed of the seeded thing at field path ``path``."""
        if self.scene_seed is None:
            raise RuntimeError("the scene seed is read before any seeded thing")
        return derive_seed(self.scene_seed, path)
