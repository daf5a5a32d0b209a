"""``render:``: sampler, samples per pixel, path depth, variant, bit depth (every key generated
from :class:`~scenegen.spec.model.render.RenderSettings`' metadata)."""
from __future__ import annotations

from scenegen.located_yaml import Node
from scenegen.spec.model.render import RenderSettings
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import read_fields, yaml_keys

KEYS = yaml_keys(RenderSettings)


def parse_render(node: Node | None, ctx: ParseContext) -> RenderSettings:
    if node is None:
        return RenderSettings()
    f = node.as_mapping().check(optional=KEYS)
    values = read_fields(f, RenderSettings)
    if values["max_depth"] == 0:
        raise f.get("max_depth").error("expected -1 (unbounded) or a positive integer, got 0")
    # No warning when the sampler rounds spp up: `render` asks for the count it takes and says so
    # in its summary ('spp 1 (sampler takes 4)', whatever --spp overrides), `validate` in its line.
    return RenderSettings(**values, where=node.where)
