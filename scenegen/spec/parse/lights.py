"""``lights:``: area, point, spot, constant (environment), envmap and directional lights."""
from __future__ import annotations

import math

from scenegen.assets.checks import ENVMAP_SUFFIXES
from scenegen.located_yaml import Node
from scenegen.spec.model import lights as ml
from scenegen.spec.model.meta import WORLD_UP
from scenegen.spec.model.views import LookAt
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_color, read_float, read_floats, read_vec3
from scenegen.spec.parse.transforms import POSE_KEYS, aim, parse_rigid

KEYS = {
    "area": ("size", "radiance", "transform", "position", "look_at", "up"),
    "point": ("position", "intensity"),
    "spot": ("position", "target", "intensity", "cutoff_deg", "beam_width_deg"),
    "constant": ("radiance",),
    "envmap": ("path", "scale", "rotation_z_deg"),
    "directional": ("direction_to_light", "irradiance"),
}
REQUIRED = {"point": ("position", "intensity"), "spot": ("position", "target", "intensity"),
            "constant": ("radiance",), "envmap": ("path",), "area": ("radiance",),
            "directional": ("direction_to_light", "irradiance")}
CLASSES = {"area": ml.AreaLight, "point": ml.PointLight, "spot": ml.SpotLight,
           "constant": ml.ConstantLight, "envmap": ml.EnvmapLight,
           "directional": ml.DirectionalLight}


def default_light_name(index: int) -> str:
    return f"light{index}"


def parse_light(node: Node, index: int, ctx: ParseContext) -> ml.Light:
    f = node.as_mapping("a light (a mapping with 'type')")
    kind = f.req("type").as_enum(ml.LIGHT_TYPES, "light type")
    f.check(required=("type",) + REQUIRED[kind], optional=("name",) + KEYS[kind])
    name = f.get("name").as_name("a light name") if "name" in f else default_light_name(index)
    w = node.where
    C = CLASSES[kind]
    if kind == "point":
        return C(name=name, position=read_vec3(f, C, "position"),
                 intensity=read_color(f.get("intensity"), C, "intensity"), where=w)
    if kind == "directional":
        d = read_vec3(f, C, "direction_to_light")
        norm = math.sqrt(sum(x * x for x in d))
        if not norm > 0:
            raise f.get("direction_to_light").error("expected a non-zero direction [x, y, z], got [0, 0, 0]")
        return C(name=name, direction_to_light=d,
                 irradiance=read_color(f.get("irradiance"), C, "irradiance"), where=w)
    if kind == "constant":
        return C(name=name, where=w, radiance=read_color(f.get("radiance"), C, "radiance"))
    if kind == "envmap":
        path, written = f.get("path").as_path(ENVMAP_SUFFIXES, "environment image")
        return C(name=name, path=path, path_as_written=written, scale=read_float(f, C, "scale"),
                 rotation_z_deg=read_float(f, C, "rotation_z_deg"), where=w)
    if kind == "spot":
        cutoff = read_float(f, C, "cutoff_deg")
        beam = read_float(f, C, "beam_width_deg", default=ml.BEAM_WIDTH_FRACTION * cutoff,
                          hi=cutoff)
        pos, tgt = read_vec3(f, C, "position"), read_vec3(f, C, "target")
        world_from_light = aim(pos, tgt, WORLD_UP, f.get("target"))
        return C(name=name, position=pos, target=tgt, world_from_light=world_from_light,
                 intensity=read_color(f.get("intensity"), C, "intensity"), cutoff_deg=cutoff,
                 beam_width_deg=beam, where=w)
    size = read_floats(f, C, "size", 2)
    which = f.one_of(("transform", "position"))
    if which == "transform":
        for bad in ("look_at", "up"):
            if bad in f:
                raise f.get(bad).error(f"{bad!r} goes with 'position', not with 'transform'")
        tf = f.get("transform").as_mapping("a transform (translation, rotation_deg or "
                                           "rotation_quat_wxyz, order)")
        tf.check(optional=POSE_KEYS)
        world_from_light = parse_rigid(tf)
    else:
        if "look_at" not in f:
            raise f.missing("look_at", " (an area light at 'position' faces 'look_at')")
        up = read_vec3(f, LookAt, "up")  # as for a look_at view
        world_from_light = aim(f.vec3("position"), f.vec3("look_at"), up, f.get("look_at"))
    return C(name=name, size=size, world_from_light=world_from_light,
             radiance=read_color(f.get("radiance"), C, "radiance"), where=w)
