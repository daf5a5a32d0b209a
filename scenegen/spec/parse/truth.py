"""``truth:``: the per-view truth written only on request (albedo, calibrated lights)."""
from __future__ import annotations

from scenegen.located_yaml import Node
from scenegen.spec.model.truth import TruthSpec
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import read_fields, yaml_keys

KEYS = yaml_keys(TruthSpec)


def parse_truth(node: Node, ctx: ParseContext) -> TruthSpec:
    f = node.as_mapping(f"a truth section ({', '.join(KEYS)}: true or false)").check(optional=KEYS)
    values = read_fields(f, TruthSpec)
    if ctx.sequence is not None and values["albedo"]:
        raise f.get("albedo").error("albedo truth is for static scenes; this spec has a `sequence:`")
    if values["defocus"] and not any(getattr(c.optics, "lens", None) is not None
                                     for c in ctx.cameras.values()):
        ctx.warn(f.get("defocus") or node, "defocus truth is written for cameras with a thin lens (`lens:`); "
                 "no camera has one, so no view gets it")
    return TruthSpec(**values, where=node.where)
