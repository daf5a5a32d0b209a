"""The top level of a spec: reads the sections in order, each with a :class:`ParseContext` that
knows the sections before it, then resolves the views once so that degenerate placements (and
crossview pairs naming no view) are errors at validation time, not at render time."""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from scenegen.dataset.layout import check_name
from scenegen.errors import SpecError
from scenegen.located_yaml import Document, Fields, Node
from scenegen.spec.finite import check_finite
from scenegen.spec.model.limits import MAX_VIEWS
from scenegen.spec.model.meta import field_info, frozen_mapping
from scenegen.spec.model.scene import SceneSpec
from scenegen.spec.model.views import TrajectoryPath
from scenegen.spec.parse.cameras import parse_camera
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.crossview import check_pair_views, parse_crossview
from scenegen.spec.parse.lights import parse_light
from scenegen.spec.parse.materials import parse_material
from scenegen.spec.parse.annotation import check_annotations
from scenegen.spec.parse.objects import parse_object
from scenegen.spec.parse.placement import check_variation, parse_placement
from scenegen.spec.parse.read import read_int
from scenegen.spec.parse.render import parse_render
from scenegen.spec.parse.rigs import parse_rig
from scenegen.spec.parse.timeline import check_sequence, parse_sequence
from scenegen.spec.parse.truth import parse_truth
from scenegen.spec.parse.variation import parse_variation
from scenegen.spec.parse.views import parse_view_set
from scenegen.spec.sensors import SENSOR_KINDS, STREAM, section_kinds, stream_name
from scenegen.spec.views import resolve_views, view_members

TOP_LEVEL_KEYS = ("name", "description", "seed", "render", "materials", "objects", "lights",
                  "cameras", "rigs", "views", "crossview", "variation", "sequence", "truth", "placement")
#: Scene name of spec text that comes from no file.
TEXT_SCENE_NAME = "scene"


def parse_document(doc: Document) -> SceneSpec:
    """The validated spec of a composed YAML document."""
    root = doc.root
    if root.node is None:
        raise SpecError("expected a mapping at the top level (keys: "
                        f"{', '.join(TOP_LEVEL_KEYS)}), got an empty document",
                        file=doc.file, line=1)
    f = root.as_mapping("a mapping at the top level (keys: name, objects, cameras, views, ...)")
    f.check(optional=TOP_LEVEL_KEYS + tuple(k.section for k in section_kinds()))
    default_name = TEXT_SCENE_NAME if doc.file.startswith("<") else Path(doc.file).stem
    name = f.get("name").as_name("a scene name") if "name" in f else default_name
    description = (f.get("description").as_str() if "description" in f
                   else field_info(SceneSpec, "description").default)
    ctx = ParseContext(doc=doc, warnings=[])
    ctx = ctx.but(scene_seed=read_int(f, SceneSpec, "seed"))
    ctx = ctx.but(render=parse_render(f.get("render"), ctx))
    ctx = ctx.but(materials=frozen_mapping(named_section(f, "materials", parse_material, ctx)))
    ctx = ctx.but(cameras=frozen_mapping(named_section(f, "cameras", parse_camera, ctx)))
    ctx = ctx.but(sensors=frozen_mapping({k.name: frozen_mapping(named_section(f, k.section, k.parse, ctx))
                                          for k in section_kinds() if k.section in f}))  # other sensor kinds
    ctx = ctx.but(rigs=frozen_mapping(named_section(f, "rigs", parse_rig, ctx)))
    sequence = parse_sequence(f.get("sequence"), ctx) if "sequence" in f else None
    check_finite(sequence)  # the clock before the views and objects timed by it: named at its source
    ctx = ctx.but(sequence=sequence)
    objects = []  # one by one: a parent is named before its children
    for i, item in enumerate(f.get("objects").items("a list of objects") if "objects" in f else []):
        objects.append(parse_object(item, i, ctx.but(objects=tuple(objects))))
    unique_names(f.get("objects"), objects, "object")
    if any(o.annotation is not None for o in objects):
        check_annotations(objects, f.get("objects"))
    ctx = ctx.but(objects=tuple(objects))
    placement = None
    if "placement" in f:  # the dropped objects at their settled poses from here on
        placement, placed = parse_placement(f.get("placement"), f.get("objects"), ctx)
        ctx = ctx.but(objects=placed)
    lights = list_section(f, "lights", parse_light, ctx)
    unique_names(f.get("lights"), lights, "light")
    ctx = ctx.but(lights=tuple(lights))  # named by view sets' `lights:`
    view_sets = list_section(f, "views", parse_view_set, ctx)
    check_view_count(f.get("views"), view_sets, ctx.rigs)  # before any pose is made
    check_stream_members(f.get("views"), view_sets, ctx.rigs, ctx.sensors)
    crossview, pair_views = parse_crossview(f.get("crossview"), ctx) if "crossview" in f \
        else (None, ())
    variation = parse_variation(f.get("variation"), ctx) if "variation" in f else None
    truth = parse_truth(f.get("truth"), ctx) if "truth" in f else None
    if placement is not None:
        check_variation(placement, variation, ctx.objects)
    spec = SceneSpec(
        name=name, description=description, seed=ctx.scene_seed, render=ctx.render,
        materials=ctx.materials, objects=ctx.objects, lights=ctx.lights, cameras=ctx.cameras,
        rigs=ctx.rigs, sensors=ctx.sensors, view_sets=tuple(view_sets), file=doc.file, base_dir=doc.base_dir,
        warnings=tuple(ctx.warnings), crossview=crossview, variation=variation, sequence=sequence,
        truth=truth, placement=placement)
    if truth is not None and truth.objects and not any(o.annotation is not None for o in ctx.objects):
        raise f.get("truth").as_mapping().get("objects").error(
            "object truth is written for objects with an `annotation:`; no object has one")
    if truth is not None and truth.albedo:
        moving = [o.name for o in objects if o.motion is not None and not o.motion.is_static] + \
                 [vs.prefix for vs in view_sets if vs.motion is not None and not vs.motion.is_static]
        if moving:
            raise f.get("truth").as_mapping().get("albedo").error(
                f"albedo truth is for a still camera over a static scene; {moving[0]!r} moves (`motion:`)")
    check_finite(spec)  # derived numbers too (k / fps): nothing infinite reaches the renderer or the JSON
    views = resolve_views(spec)  # degenerate placements are errors now, not at render time
    if sequence is not None:
        check_sequence(f, spec)
    check_pair_views(pair_views, views)
    return spec


def named_section(f: Fields, key: str, parse: Callable, ctx: ParseContext) -> dict:
    """A mapping name -> thing; ``parse(node, name, ctx)``."""
    node = f.get(key)
    if node is None:
        return {}
    section = node.as_mapping(f"a mapping of names to {key}")
    out = {}
    for name in section.keys():
        section.key_node(name).as_name(f"a {key[:-1]} name")
        out[name] = parse(section.value(name), name, ctx)
    return out


def list_section(f: Fields, key: str, parse: Callable, ctx: ParseContext) -> list:
    """A list of things; ``parse(node, index, ctx)``."""
    node = f.get(key)
    if node is None:
        return []
    return [parse(item, i, ctx) for i, item in enumerate(node.items(f"a list of {key}"))]


def unique_names(section: Node | None, things, what: str) -> None:
    seen: dict[str, int | None] = {}
    items = section.items() if things else []  # once: linear in the number of things
    for item, thing in zip(items, things):
        name_node = item.as_mapping().get("name") or item
        if thing.name in seen:
            raise name_node.error(f"duplicate {what} name {thing.name!r} (first at line "
                                  f"{seen[thing.name]})")
        seen[thing.name] = name_node.line


def planned_views(vs) -> int:
    """How many views a view set makes (rig members counted), without making them."""
    p = vs.placement
    n = {"orbit": lambda: p.count * len(p.elevations_deg), "look_at": lambda: len(p.entries),
         "poses": lambda: len(p.world_from_cam), "trajectory": lambda: len(p.times_s)}.get(p.kind, lambda: p.count)()
    return n


def check_stream_members(node, view_sets, rigs, sensors=None) -> None:
    """A rig member of a stream kind samples at its frames' times, so its view set needs them (a
    ``trajectory:`` placement), and its stream ``<view set>_<member>`` needs a name of its own;
    then the kind's own rules on the view set (``SensorKind.check_view_set``)."""
    seen: dict[str, int] = {}
    for i, (item, vs) in enumerate(zip(node.items() if view_sets else [], view_sets)):
        for mb in rigs[vs.rig].members if vs.rig is not None else ():
            if SENSOR_KINDS[mb.kind].produces != STREAM:
                continue
            if not isinstance(vs.placement, TrajectoryPath):
                raise item.error(f"rig {vs.rig!r} holds the {mb.kind} {mb.name!r}, whose stream samples over "
                                 "time: its view set needs times (a `trajectory:` placement)")
            kind = SENSOR_KINDS[mb.kind]
            if kind.check_view_set is not None:
                kind.check_view_set(mb, (sensors or {}).get(mb.kind, {})[mb.sensor], vs, item)
            name = stream_name(vs, mb)
            try:
                check_name("stream", name)
            except ValueError as e:
                raise item.error(str(e)) from None
            if name in seen:
                raise item.error(f"stream {name!r} is made by views[{seen[name]}] too; give the view sets "
                                 "distinct `name`s")
            seen[name] = i


def check_view_count(node, view_sets, rigs) -> None:
    total = sum(planned_views(vs) * (len(view_members(rigs[vs.rig])) if vs.rig is not None else 1)
                for vs in view_sets)
    if total > MAX_VIEWS:
        raise node.error(f"the view sets make {total:,} views; at most {MAX_VIEWS:,} per run (MAX_VIEWS, "
                         "docs/scene_spec.md 'Limits'): split the run into several datasets")
