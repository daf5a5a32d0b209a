"""The optional top-level ``placement:`` section: objects placed by a rigid-body simulation.

``type: drop`` releases the named objects above a support object, seeded, and lets MuJoCo settle
them (:mod:`scenegen.physics`); their settled poses replace their transforms and are recorded
here (``poses``), in the resolved spec and in ``to_yaml``, so a spec that carries them is the
same scene without running the engine. Parsed by :mod:`scenegen.spec.parse.placement`;
documented in ``docs/scene_spec.md`` ("Placement").
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from scenegen.errors import Where
from scenegen.spec.model.meta import SEED_MAX, frozen_mapping, param, part, where_field

PLACEMENT_TYPES = ("drop",)
DROP_ORIENTATIONS = ("random", "yaw")


@dataclass(frozen=True, kw_only=True, eq=False)
class DropPlacement:
    objects: tuple[str, ...] = part(unit="names of the dropped objects, released in this order")
    onto: str = param(unit="object name", kind="str")  # the static support (its transform
    # stays); the objects rest on its top
    seed: int = param(unit="seed", label="", lo=0, hi=SEED_MAX,
                      derived="seed32(scene seed, 'placement')")  # release poses
    region_min: tuple[float, float] | None = param(
        None, unit="metres", key="region.min",
        doc_default="the support's world x, y bounds, inset by each object's bounding radius")
    region_max: tuple[float, float] | None = param(None, unit="metres", key="region.max")
    # box of the release centres in world x, y (YAML region: {min: [x, y], max: [x, y]})
    drop_height_m: float = param(0.05, unit="metres", lo=0.0)  # gap between the support's top
    # and the lowest point of each released object's bounding sphere
    orientation: str = param("random", unit="orientation", choices=DROP_ORIENTATIONS)  # 'random':
    # uniform rotation; 'yaw': the written rotation turned about world +z
    friction: float = param(0.8, unit="Coulomb coefficient", lo=0.0, lo_open=True)  # sliding
    # friction of every contact
    settle_s: float = param(5.0, unit="seconds (simulated)", lo=0.0, lo_open=True, hi=60.0)
    # at most; the drop stops once every object has rested for 0.2 s
    rest_speed_m_s: float = param(0.001, unit="metres / second", lo=0.0, lo_open=True)  # no
    # point of a resting object moves faster
    poses: Mapping[str, object] = part(default_factory=frozen_mapping,
                                       unit="object name -> settled world_from_object (Rigid3); "
                                            "given in the YAML they replace the simulation")
    type: str = field(default="drop", init=False)
    where: Where | None = where_field()
