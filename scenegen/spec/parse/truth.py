"""``truth:``: the per-view truth written only on request (albedo, calibrated lights)."""
from __future__ import annotations

from scenegen.located_yaml import Node
from scenegen.spec.model.meta import spec_fields
from scenegen.spec.model.truth import TruthSpec
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_bool

KEYS = tuple(fi.name for fi in spec_fields(TruthSpec))


def parse_truth(node: Node, ctx: ParseContext) -> TruthSpec:
    f = node.as_mapping(f"a truth section ({', '.join(KEYS)}: true or false)").check(optional=KEYS)
    if ctx.sequence is not None and read_bool(f, TruthSpec, "albedo"):
        raise f.get("albedo").error("albedo truth is for static scenes; this spec has a `sequence:`")
    defocus = read_bool(f, TruthSpec, "defocus")
    if defocus and not any(getattr(c.optics, "lens", None) is not None for c in ctx.cameras.values()):
        ctx.warn(f.get("defocus") or node, "defocus truth is written for cameras with a thin lens (`lens:`); "
                 "no camera has one, so no view gets it")
    return TruthSpec(albedo=read_bool(f, TruthSpec, "albedo"), lights=read_bool(f, TruthSpec, "lights"),
                     defocus=defocus, where=node.where)
