"""``crossview:`` (docs/crossview.md): which view pairs get cross-view truth, flow, stereo,
match sets, SIFT, target corners. Explicit pairs name views, checked once views are resolved."""
from __future__ import annotations

from typing import Sequence

from scenegen.located_yaml import Node, suggest
from scenegen.spec.model.crossview import CrossviewSpec, MatchSetSpec
from scenegen.spec.model.meta import spec_fields
from scenegen.spec.model.views import View
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import read_fields, yaml_keys
from scenegen.spec.parse.read import read_enum, seed_or_none

KEYS = tuple(fi.key for fi in spec_fields(CrossviewSpec))
MATCH_KEYS = yaml_keys(MatchSetSpec)
#: (view name, its node) of every view an explicit pair names, to check against resolved views.
NamedViews = tuple[tuple[str, Node], ...]


def parse_crossview(node: Node, ctx: ParseContext) -> tuple[CrossviewSpec, NamedViews]:
    f = node.as_mapping("a crossview section (pairs, flow, stereo, matches, sift, ...)")
    f.check(optional=KEYS)
    C = CrossviewSpec
    named: list[tuple[str, Node]] = []
    pn = f.get("pairs")
    if pn is not None and pn.is_sequence:
        out = []
        for item in pn.items("a list of [view_a, view_b] pairs"):
            names = item.items("a pair [view_a, view_b] of view names")
            if len(names) != 2:
                raise item.error(f"expected a pair [view_a, view_b] of view names, got "
                                 f"{len(names)} items")
            a, b = (n.as_str("a view name") for n in names)
            if a == b:
                raise names[1].error(f"a pair needs two different views, got {a!r} twice")
            out.append((a, b))
            named.extend(zip((a, b), names))
        if not out:
            raise pn.error("expected at least one pair, got an empty list (use pairs: none)")
        pairs = tuple(out)
    else:
        pairs = read_enum(f, C, "pairs")
    matches = parse_matches(f.get("matches"), ctx) if "matches" in f else None
    values = read_fields(f, C, skip=("pairs",))
    lo, hi = values["ir_depth_range_m"]
    if not lo < hi:
        raise f.get("ir_depth_range_m").error(f"expected min < max, got {[lo, hi]}")
    spec = C(pairs=pairs, matches=matches, **values, where=node.where)
    return spec, tuple(named)


def parse_matches(node: Node, ctx: ParseContext) -> MatchSetSpec:
    mf = node.as_mapping("a match-set mapping (count, sigma_px, ...)").check(optional=MATCH_KEYS)
    M = MatchSetSpec
    values = read_fields(mf, M)
    near = values["near_miss_px"]
    if near[0] > near[1]:
        raise mf.get("near_miss_px").error(f"expected min <= max, got {list(near)}")
    seed = seed_or_none(mf, M)
    return M(**values, seed=ctx.seed_for(node.path) if seed is None else seed, where=node.where)


def check_pair_views(named: NamedViews, views: Sequence[View]) -> None:
    """Explicit crossview pairs must name resolved views."""
    names = [v.name for v in views]
    for name, node in named:
        if name not in names:
            shown = ", ".join(names[:8]) + (", ..." if len(names) > 8 else "") or "none"
            raise node.error(f"undefined view {name!r}{suggest(name, names)}; views: {shown}")
