"""``variation:``: seeded ranges for ``scenegen render --variants N``, validated against the
objects, lights and cameras they name (:mod:`scenegen.spec.model.variation`)."""
from __future__ import annotations

from scenegen.located_yaml import Node, suggest
from scenegen.spec.model import variation as mv
from scenegen.spec.model.geometry import Blob
from scenegen.spec.model.lights import AreaLight, PointLight, SpotLight
from scenegen.spec.model.materials import PROCEDURAL_TEXTURE_KINDS, DiffuseMaterial, PlasticMaterial
from scenegen.spec.model.meta import field_info
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import read_fields, record_mapping
from scenegen.spec.parse.read import seed_or_none

#: Field path the variation seed is derived from (with the scene seed).
SEED_PATH = "variation"


def parse_box(node: Node, cls: type, name: str):
    """{min: [x, y, z], max: [x, y, z]} with max >= min, each in the field's range."""
    meta = field_info(cls, name).meta
    unit = meta.unit
    f = node.as_mapping(f"a box {{min: [x, y, z], max: [x, y, z]}} ({unit})").check(
        required=("min", "max"))
    a = f.get("min").as_floats(3, unit, lo=meta.lo, hi=meta.hi)
    b = f.get("max").as_floats(3, unit, lo=meta.lo, hi=meta.hi)
    if any(x > y for x, y in zip(a, b)):
        raise f.get("max").error(f"expected max >= min on every axis, got min {list(a)}, "
                                 f"max {list(b)}")
    return a, b


def named_entries(section: Node, names: list[str], what: str):
    """(name, node) per entry of a mapping keyed by names of ``what``s that exist."""
    f = section.as_mapping(f"a mapping of {what} names to their variation")
    for name in f.keys():
        if name not in names:
            raise f.key_node(name).error(f"undefined {what} {name!r}{suggest(name, names)}; "
                                         f"{what}s: {', '.join(names) or 'none'}")
        yield name, f.value(name)


def parse_variation(node: Node, ctx: ParseContext) -> mv.VariationSpec:
    """Parse and validate the ``variation:`` section against the parsed scene."""
    f = node.as_mapping("a variation section (seed, objects, lights, cameras, views)")
    f.check(optional=("seed", "objects", "lights", "cameras", "views"))
    seed = seed_or_none(f, mv.VariationSpec)
    seed = ctx.seed_for(SEED_PATH) if seed is None else seed
    objs = [parse_object_variation(name, vn, ctx)
            for name, vn in named_entries(f.get("objects"), [o.name for o in ctx.objects],
                                          "object")] if "objects" in f else []
    lts = [parse_light_variation(name, vn, ctx)
           for name, vn in named_entries(f.get("lights"), [li.name for li in ctx.lights],
                                         "light")] if "lights" in f else []
    cams = [parse_camera_variation(name, vn, ctx)
            for name, vn in named_entries(f.get("cameras"), list(ctx.cameras),
                                          "camera")] if "cameras" in f else []
    views = None
    if "views" in f:
        vf = record_mapping(f.get("views"), mv.PoseJitter, "a pose jitter")
        views = mv.PoseJitter(**read_fields(vf, mv.PoseJitter), where=f.get("views").where)
    return mv.VariationSpec(seed=seed, objects=tuple(objs), lights=tuple(lts),
                            cameras=tuple(cams), views=views, where=node.where)


def parse_object_variation(name: str, vn: Node, ctx: ParseContext) -> mv.ObjectVariation:
    O = mv.ObjectVariation
    of = vn.as_mapping("an object variation (position, yaw_deg, color, reseed)")
    of.check(optional=("position", "yaw_deg", "color", "reseed"))
    obj = next(o for o in ctx.objects if o.name == name)
    moving = [k for k in ("position", "yaw_deg") if k in of and getattr(obj, "animation", None) is not None]
    if moving:
        raise of.get(moving[0]).error(f"object {name!r} moves over the sequence (trajectory, parent, "
                                      f"joint or visible_s): its placement comes from there, so "
                                      f"{moving[0]!r} cannot vary it")
    pos = parse_box(of.get("position"), O, "position_min") if "position" in of else (None, None)
    col = (None, None)
    if "color" in of:
        mat = obj.material
        if getattr(obj.geometry, "own_materials", False):
            raise of.get("color").error(
                f"object {name!r} renders its mesh file's own materials; colour variation needs a "
                "spec `material:` (diffuse or plastic with a colour) on the object")
        if not isinstance(mat, (DiffuseMaterial, PlasticMaterial)) or mat.color is None:
            raise of.get("color").error(
                f"object {name!r} has a {mat.type} material"
                f"{' with a texture' if getattr(mat, 'texture', None) else ''}; colour variation "
                "needs a diffuse or plastic material with a colour")
        col = parse_box(of.get("color"), O, "color_min")
    values = read_fields(of, O)  # yaw_deg, reseed
    if values["reseed"]:
        tex = getattr(obj.material, "texture", None)
        procedural = tex is not None and tex.kind in PROCEDURAL_TEXTURE_KINDS
        if not procedural and not isinstance(obj.geometry, Blob):
            raise of.get("reseed").error(f"object {name!r} has neither a procedural texture nor "
                                         "a blob shape: nothing to reseed")
    return O(object=name, position_min=pos[0], position_max=pos[1], color_min=col[0],
             color_max=col[1], **values, where=vn.where)


def parse_light_variation(name: str, vn: Node, ctx: ParseContext) -> mv.LightVariation:
    L = mv.LightVariation
    lf = record_mapping(vn, L, "a light variation")
    values = read_fields(lf, L)
    light = next(li for li in ctx.lights if li.name == name)
    if values["position_jitter_m"] > 0 and not isinstance(light, (AreaLight, PointLight, SpotLight)):
        raise lf.get("position_jitter_m").error(
            f"light {name!r} is a {light.type} light, which has no position")
    return L(light=name, **values, where=vn.where)


def parse_camera_variation(name: str, vn: Node, ctx: ParseContext) -> mv.CameraVariation:
    C = mv.CameraVariation
    cf = record_mapping(vn, C, "a camera variation")
    cam = ctx.cameras[name]
    dist = field_info(C, "dist_jitter").default
    if "dist_jitter" in cf:
        n = len(cam.dist)
        if n == 0:
            raise cf.get("dist_jitter").error(
                f"camera {name!r} ({cam.model}) has no distortion coefficients to vary")
        meta = field_info(C, "dist_jitter").meta
        dist = cf.get("dist_jitter").as_floats(
            n, f"one half-width per coefficient of {name!r}'s dist", lo=meta.lo)
    return C(camera=name, **read_fields(cf, C, skip=("dist_jitter",)), dist_jitter=dist,
             where=vn.where)
