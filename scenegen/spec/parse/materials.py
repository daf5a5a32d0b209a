"""``materials:`` and inline materials: diffuse, plastic, conductor, dielectric, thin dielectric,
principled, each with optional normal/bump maps and an alpha mask; image and procedural
textures (parameter names checked against :mod:`scenegen.assets.textures`)."""
from __future__ import annotations

from scenegen.assets.textures import check_texture_size, texture_params
from scenegen.located_yaml import Node, suggest
from scenegen.spec.model import materials as mm
from scenegen.spec.model.meta import field_info, frozen_mapping, spec_fields
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import read_fields, written_fields
from scenegen.spec.parse.pbr_set import parse_pbr_set
from scenegen.spec.parse.read import read_enum, seed_or_none


def freeze(value):
    """Plain YAML data (dicts, lists) as read-only mappings and tuples."""
    if isinstance(value, dict):
        return frozen_mapping({k: freeze(v) for k, v in value.items()})
    if isinstance(value, list):
        return tuple(freeze(v) for v in value)
    return value


def parse_texture(node: Node, ctx: ParseContext) -> mm.Texture:
    f = node.as_mapping("a texture (a mapping with 'type')")
    f.check(required=("type",), optional=("path", "params", "seed"))
    kind = read_enum(f, mm.Texture, "kind", "type")
    if kind == "image":
        if "params" in f or "seed" in f:
            bad = "params" if "params" in f else "seed"
            raise f.get(bad).error(f"an image texture takes only 'path', not {bad!r}")
        path, written = f.req("path").as_path(mm.IMAGE_SUFFIXES, "image")
        return mm.Texture(kind=kind, path=path, path_as_written=written, where=node.where)
    if "path" in f:
        raise f.get("path").error(f"a {kind} texture is procedural and takes no 'path'; "
                                  "use type: image for image files")
    params = {}
    if "params" in f:
        pf = f.get("params").as_mapping("a mapping of texture parameters")
        pf.check(optional=texture_params(kind))  # names only; values are make_texture's business
        params = f.get("params").plain()
        try:
            check_texture_size(kind, params)  # before anything is allocated (MAX_TEXTURE_PIXELS)
        except ValueError as e:
            raise f.get("params").error(f"{e} (docs/scene_spec.md 'Limits')") from None
    seed = seed_or_none(f, mm.Texture)
    if seed is None:
        seed = ctx.seed_for(node.path)
    return mm.Texture(kind=kind, params=freeze(params), seed=seed, where=node.where)


MAP_KEYS = tuple(fi.key for fi in spec_fields(mm.SurfaceMaps))
CLASSES = {"diffuse": mm.DiffuseMaterial, "plastic": mm.PlasticMaterial,
           "conductor": mm.ConductorMaterial, "dielectric": mm.DielectricMaterial,
           "thin_dielectric": mm.ThinDielectricMaterial, "principled": mm.PrincipledMaterial}

#: The keys of each material type besides `type` and the maps: its written fields (and
#: `texture`, the alternative to `color`), generated from the dataclasses.
TYPE_KEYS = {kind: tuple(fi.key for fi in spec_fields(cls)
                         if fi.name == "texture" or fi in written_fields(cls))
             for kind, cls in CLASSES.items()}


def parse_map(node: Node, ctx: ParseContext) -> mm.Texture:
    """A map: a texture mapping, or an image path (shorthand for {type: image, path: ...})."""
    if node.is_mapping:
        return parse_texture(node, ctx)
    path, written = node.as_path(mm.IMAGE_SUFFIXES, "image")
    return mm.Texture(kind="image", path=path, path_as_written=written, where=node.where)


def parse_maps(f, node: Node, ctx: ParseContext) -> mm.SurfaceMaps | None:
    """The normal map, bump map and alpha mask keys of a material (None when it has none)."""
    if not any(k in f for k in MAP_KEYS):
        return None
    S = mm.SurfaceMaps
    for k in ("bump_scale", "alpha_cutoff", "alpha_blend"):
        owner = "bump_map" if k == "bump_scale" else "alpha"
        if k in f and owner not in f:
            raise f.get(k).error(f"{k!r} goes with {owner!r}, which is missing")
    get = lambda k: parse_map(f.get(k), ctx) if k in f else None
    return S(normal_map=get("normal_map"), bump_map=get("bump_map"), alpha=get("alpha"),
             **read_fields(f, S), where=node.where)


def _color_or_texture(f, cls, ctx: ParseContext):
    which = f.one_of(("color", "texture"), required=False)
    color = f.get("color").as_color() if which == "color" else None
    if color is not None and max(color) > field_info(cls, "color").meta.hi:
        raise f.get("color").error(f"expected reflectance in [0, 1] (linear RGB), got {color}")
    texture = parse_texture(f.get("texture"), ctx) if which == "texture" else None
    if which is None:
        color = field_info(cls, "color").default
    return color, texture


def parse_material(node: Node, name: str | None, ctx: ParseContext) -> mm.Material:
    if node.is_null:
        raise node.error("expected a material (a mapping with 'type'), got nothing (null)")
    f = node.as_mapping("a material (a mapping with 'type')")
    if "type" not in f:
        f.check(required=("type",), optional=f.keys())
    kind = f.get("type").as_enum(mm.MATERIAL_TYPES, "material type")
    cls = CLASSES[kind]
    f.check(required=("type",), optional=TYPE_KEYS[kind] + MAP_KEYS + (("pbr_set",) if kind == "principled" else ()))
    if "pbr_set" in f:  # a texture set folder gives the texture and the data maps
        pbr, texture = parse_pbr_set(f.get("pbr_set"), f)
        return cls(name=name, maps=parse_maps(f, node, ctx), where=node.where, color=None, texture=texture,
                   pbr_set=pbr, **read_fields(f, cls, skip=("color",)))
    common = {"name": name, "maps": parse_maps(f, node, ctx), "where": node.where,
              **read_fields(f, cls, skip=("color", "material"))}
    if kind == "conductor":
        cname = field_info(cls, "material").default
        if "material" in f:
            cname = f.get("material").as_str(field_info(cls, "material").meta.shown)
            if cname not in mm.CONDUCTOR_NAMES:
                raise f.get("material").error(
                    f"unknown conductor {cname!r}{suggest(cname, mm.CONDUCTOR_NAMES)}; "
                    "Mitsuba knows e.g. 'Al', 'Ag', 'Au', 'Cu', 'Cr', 'W'")
        return cls(material=cname, **common)
    if "color" not in TYPE_KEYS[kind]:
        return cls(**common)
    color, texture = _color_or_texture(f, cls, ctx)
    return cls(color=color, texture=texture, **common)
