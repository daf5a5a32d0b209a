"""``render:``: sampler, samples per pixel, path depth, variant, bit depth."""
from __future__ import annotations

from scenegen.located_yaml import Node
from scenegen.spec.model.meta import spec_fields
from scenegen.spec.model.render import RenderSettings
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_enum, read_int

KEYS = tuple(fi.name for fi in spec_fields(RenderSettings))


def parse_render(node: Node | None, ctx: ParseContext) -> RenderSettings:
    if node is None:
        return RenderSettings()
    f = node.as_mapping().check(optional=KEYS)
    R = RenderSettings
    spp = read_int(f, R, "spp")
    max_depth = read_int(f, R, "max_depth")
    if max_depth == 0:
        raise f.get("max_depth").error("expected -1 (unbounded) or a positive integer, got 0")
    sampler = read_enum(f, R, "sampler")
    # No warning when the sampler rounds spp up: `render` asks for the count it takes and says so
    # in its summary ('spp 1 (sampler takes 4)', whatever --spp overrides), `validate` in its line.
    return RenderSettings(
        spp=spp, max_depth=max_depth, seed=read_int(f, R, "seed"),
        variant=read_enum(f, R, "variant"), bit_depth=read_enum(f, R, "bit_depth"),
        sampler=sampler, motion_subframes=read_int(f, R, "motion_subframes"), where=node.where)
