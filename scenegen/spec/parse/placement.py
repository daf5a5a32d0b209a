"""``placement:``: objects dropped onto a support and settled by MuJoCo at parse time
(:mod:`scenegen.physics`), or placed at the settled poses the section records (``poses:``, as
:func:`scenegen.spec.to_yaml.to_yaml` writes them), without the engine.

The dropped objects' transforms become their settled poses (their written scale kept). Errors
name the section's field: an unknown or repeated object, a flat object (a plane, a board), a
moving one, a translation written for a dropped object, an object that fits nowhere on the
support, one that has not come to rest in ``settle_s`` (it fell off the support, say).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from scenegen.errors import SpecError
from scenegen.located_yaml import Fields, Node, suggest
from scenegen.spec.model.geometry import TARGET_KINDS, Blob, SceneObject, Transform
from scenegen.spec.model.meta import field_info, frozen_mapping
from scenegen.spec.model.placement import PLACEMENT_TYPES, DropPlacement
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import check_keys, read_fields
from scenegen.spec.parse.read import seed_or_none
from scenegen.spec.parse.transforms import parse_pose

#: Field path the drop's seed is derived from (with the scene seed).
SEED_PATH = "placement"
#: Geometry kinds that cannot fall: no volume to collide with.
FLAT_KINDS = ("plane",) + TARGET_KINDS
#: Transform keys a dropped object may give: its scale and (for orientation 'yaw') its rotation.
DROPPED_TRANSFORM_KEYS = ("scale", "rotation_deg", "rotation_quat_wxyz", "order")


def parse_placement(node: Node, objects_node: Node | None,
                    ctx: ParseContext) -> tuple[DropPlacement, tuple[SceneObject, ...]]:
    """The placement record and ``ctx.objects`` with the dropped ones at their settled poses."""
    f = node.as_mapping("a placement section (type: drop, objects, onto, region, ...)")
    f.req("type").as_enum(PLACEMENT_TYPES, "placement type")
    check_keys(f, DropPlacement, required=("type", "objects"), optional=("region", "poses"))
    values = read_fields(f, DropPlacement)
    by_name = {o.name: o for o in ctx.objects}
    onto = values["onto"]
    if onto not in by_name:
        raise f.get("onto").error(f"undefined object {onto!r}{suggest(onto, by_name)}; objects: "
                                  f"{', '.join(by_name) or 'none'}")
    if by_name[onto].animation is not None or by_name[onto].motion is not None:
        raise f.get("onto").error(f"the support {onto!r} moves (`motion:` or the sequence); it must stand still")
    names = _dropped_names(f.get("objects"), by_name, onto, objects_node)
    seed = seed_or_none(f, DropPlacement)
    region = _region(f.get("region")) if "region" in f else (None, None)
    spec = DropPlacement(objects=tuple(names), seed=ctx.seed_for(SEED_PATH) if seed is None else seed,
                         region_min=region[0], region_max=region[1], **values, where=node.where)
    if "poses" in f:
        poses = _recorded_poses(f.get("poses"), names)
    else:
        # the engine (MuJoCo) and the meshes (trimesh) load only for a spec that drops objects:
        # `scenegen validate` of any other spec stays light
        from scenegen.spec.parse.placement_drop import simulate
        poses = simulate(spec, [by_name[n] for n in names], by_name[onto], f)
    spec = dataclasses.replace(spec, poses=frozen_mapping(poses))
    objects = tuple(dataclasses.replace(o, transform=Transform(world_from_object=poses[o.name],
                                                               scale=o.transform.scale))
                    if o.name in poses else o for o in ctx.objects)
    return spec, objects


def _dropped_names(node: Node, by_name: dict, onto: str, objects_node: Node | None) -> list[str]:
    items = node.items("a list of object names")
    if not items:
        raise node.error("expected at least one object name to drop")
    names: list[str] = []
    for item in items:
        name = item.as_str("an object name")
        if name not in by_name:
            raise item.error(f"undefined object {name!r}{suggest(name, by_name)}; objects: {', '.join(by_name)}")
        if name == onto or name in names:
            raise item.error(f"object {name!r} is {'the support' if name == onto else 'named twice'}")
        obj = by_name[name]
        if obj.geometry.kind in FLAT_KINDS:
            raise item.error(f"object {name!r} is a {obj.geometry.kind}: it has no volume to collide with")
        if obj.animation is not None or obj.motion is not None:
            raise item.error(f"object {name!r} moves (`motion:` or the sequence); a dropped object comes to rest")
        _check_written_transform(objects_node, obj, name)
        names.append(name)
    children = [o for o in by_name.values() if o.animation is not None and o.animation.parent in names]
    if children:
        raise node.error(f"object {children[0].name!r} hangs from the dropped object "
                         f"{children[0].animation.parent!r}; a dropped object has no children")
    return names


def _check_written_transform(objects_node: Node | None, obj: SceneObject, name: str) -> None:
    """A dropped object's position comes from the drop: its transform gives scale and rotation."""
    item = objects_node.items()[obj.object_id - 1].as_mapping()
    tf = item.get("transform")
    if tf is None:
        return
    for key in tf.as_mapping().keys():
        if key not in DROPPED_TRANSFORM_KEYS:
            raise tf.as_mapping().key_node(key).error(
                f"object {name!r} is dropped by `placement:`, which places it: its transform may give "
                f"{', '.join(DROPPED_TRANSFORM_KEYS)}, not {key!r}")


def _region(node: Node) -> tuple[tuple[float, float], tuple[float, float]]:
    unit = field_info(DropPlacement, "region_min").meta.unit
    f = node.as_mapping(f"a box {{min: [x, y], max: [x, y]}} ({unit}, world)").check(required=("min", "max"))
    a, b = f.get("min").as_floats(2, unit), f.get("max").as_floats(2, unit)
    if any(x > y for x, y in zip(a, b)):
        raise f.get("max").error(f"expected max >= min on x and y, got min {list(a)}, max {list(b)}")
    return a, b


def _recorded_poses(node: Node, names: list[str]) -> dict:
    f = node.as_mapping("a mapping of the dropped objects' names to their settled poses (4x4 rows)")
    f.check(required=names)
    return {name: parse_pose(f.get(name)) for name in names}


def check_variation(placement: DropPlacement, variation, objects: tuple[SceneObject, ...]) -> None:
    """A variation may not move an object of the drop (nor the support), nor reshape a dropped blob:
    the settled poses hold for the objects as written."""
    if variation is None:
        return
    involved = set(placement.objects) | {placement.onto}
    geometry = {o.name: o.geometry for o in objects}
    for ov in variation.objects:
        if ov.object not in involved:
            continue
        what = ("position" if ov.position_min is not None else "yaw_deg" if ov.yaw_deg is not None
                else "reseed" if ov.reseed and isinstance(geometry[ov.object], Blob) else None)
        if what is not None:
            raise SpecError.at(ov.where, f"object {ov.object!r} takes part in the drop of `placement:`; "
                               f"{what!r} would change where it rests (vary it before the drop: not supported)")
