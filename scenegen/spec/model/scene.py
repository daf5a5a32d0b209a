"""The whole spec: :class:`SceneSpec`, what :func:`scenegen.spec.load_spec` returns."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from scenegen.spec.model.cameras import CameraSpec, Rig
from scenegen.spec.model.crossview import CrossviewSpec
from scenegen.spec.model.geometry import SceneObject
from scenegen.spec.model.lights import Light
from scenegen.spec.model.materials import Material
from scenegen.spec.model.placement import DropPlacement
from scenegen.spec.model.meta import SEED_MAX, frozen_mapping, param, part
from scenegen.spec.model.render import RenderSettings
from scenegen.spec.model.truth import TruthSpec
from scenegen.spec.model.variation import VariationSpec
from scenegen.spec.model.views import ViewSet


@dataclass(frozen=True, kw_only=True, eq=False)
class SceneSpec:
    name: str = param(unit="scene name", derived="the spec file's stem ('scene' for text)")
    description: str = param("", unit="free text")
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX)  # scene seed: default seeds
    # of procedural textures, blobs, random views and match sets
    render: RenderSettings = part(default_factory=RenderSettings, unit="render settings")
    materials: Mapping[str, Material] = part(default_factory=frozen_mapping, unit="by name")
    objects: tuple[SceneObject, ...] = part((), unit="the `objects:` list")
    lights: tuple[Light, ...] = part((), unit="the `lights:` list")
    cameras: Mapping[str, CameraSpec] = part(default_factory=frozen_mapping, unit="by name")
    rigs: Mapping[str, Rig] = part(default_factory=frozen_mapping, unit="by name")
    sensors: Mapping[str, Mapping[str, Any]] = part(default_factory=frozen_mapping, unit="the sensors of "
                                                    "the kinds other than cameras (scenegen.spec.sensors), "
                                                    "by kind, then by name")
    view_sets: tuple[ViewSet, ...] = part((), unit="the `views:` list")
    file: str | None = part(None, unit="the spec file as named by the user ('<string>' for text)")
    base_dir: Path = part(default_factory=Path.cwd, unit="directory relative paths resolve "
                                                         "against")
    warnings: tuple[str, ...] = part((), unit="non-fatal remarks, each 'file:line: field: "
                                              "message'")
    crossview: CrossviewSpec | None = part(None, unit="cross-view truth to write; None = none")
    variation: VariationSpec | None = part(None, unit="seeded ranges for `scenegen render "
                                                      "--variants N`; None = none declared")
    sequence: Any = part(None, unit="scenegen.spec.model.timeline.SequenceSpec: the clock of a "
                                    "sequence; None = a static scene")
    truth: TruthSpec | None = part(None, unit="per-view truth written on request (albedo, "
                                             "lights); None = none", omit_default=True)
    placement: DropPlacement | None = part(None, unit="objects dropped onto a support and settled "
                                                     "(their settled poses recorded); None = none",
                                                omit_default=True)
    variant: Mapping[str, Any] | None = part(None, unit="a derived variant's index, seed and "
                                                        "drawn values "
                                                        "(scenegen.spec.variants.derive_variant); "
                                                        "None for the spec as written")
