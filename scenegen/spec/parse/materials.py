"""``materials:`` and inline materials: diffuse, plastic, conductor; image and procedural
textures (parameter names checked against :mod:`scenegen.assets.textures`)."""
from __future__ import annotations

from scenegen.assets.textures import check_texture_size, texture_params
from scenegen.located_yaml import Node, suggest
from scenegen.spec.model import materials as mm
from scenegen.spec.model.meta import field_info, frozen_mapping
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_enum, read_float, seed_or_none


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


def parse_material(node: Node, name: str | None, ctx: ParseContext) -> mm.Material:
    if node.is_null:
        raise node.error("expected a material (a mapping with 'type'), got nothing (null)")
    f = node.as_mapping("a material (a mapping with 'type')")
    if "type" not in f:
        f.check(required=("type",), optional=f.keys())
    kind = f.get("type").as_enum(mm.MATERIAL_TYPES, "material type")
    if kind == "conductor":
        C = mm.ConductorMaterial
        f.check(required=("type",), optional=("material", "roughness"))
        cname = field_info(C, "material").default
        if "material" in f:
            cname = f.get("material").as_str(field_info(C, "material").meta.shown)
            if cname not in mm.CONDUCTOR_NAMES:
                raise f.get("material").error(
                    f"unknown conductor {cname!r}{suggest(cname, mm.CONDUCTOR_NAMES)}; "
                    "Mitsuba knows e.g. 'Al', 'Ag', 'Au', 'Cu', 'Cr', 'W'")
        return C(name=name, material=cname, roughness=read_float(f, C, "roughness"),
                 where=node.where)
    cls = mm.PlasticMaterial if kind == "plastic" else mm.DiffuseMaterial
    extra = ("roughness", "ior") if kind == "plastic" else ()
    f.check(required=("type",), optional=("color", "texture") + extra)
    which = f.one_of(("color", "texture"), required=False)
    color = f.get("color").as_color() if which == "color" else None
    if color is not None and max(color) > field_info(cls, "color").meta.hi:
        raise f.get("color").error(f"expected reflectance in [0, 1] (linear RGB), got {color}")
    texture = parse_texture(f.get("texture"), ctx) if which == "texture" else None
    if which is None:
        color = field_info(cls, "color").default
    if kind == "diffuse":
        return cls(name=name, color=color, texture=texture, where=node.where)
    return cls(name=name, color=color, texture=texture, roughness=read_float(f, cls, "roughness"),
               ior=read_float(f, cls, "ior"), where=node.where)
