"""``lights:``: area, point, spot, constant (environment), envmap and directional lights."""
from __future__ import annotations

import math

from scenegen.assets.checks import ENVMAP_SUFFIXES
from scenegen.located_yaml import Node
from scenegen.spec.model import lights as ml
from scenegen.spec.model.meta import WORLD_UP
from scenegen.spec.model.views import LookAt
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import check_keys, read_fields
from scenegen.spec.parse.read import read_float, read_vec3
from scenegen.spec.parse.transforms import POSE_KEYS, aim, parse_rigid

#: Keys read by hand besides the generated ones (those of the light's dataclass fields).
EXTRA_KEYS = {"area": ("transform", "position", "look_at", "up"), "envmap": ("path",)}
EXTRA_REQUIRED = {"envmap": ("path",)}
CLASSES = {"area": ml.AreaLight, "point": ml.PointLight, "spot": ml.SpotLight,
           "constant": ml.ConstantLight, "envmap": ml.EnvmapLight,
           "directional": ml.DirectionalLight}


def default_light_name(index: int) -> str:
    return f"light{index}"


def parse_light(node: Node, index: int, ctx: ParseContext) -> ml.Light:
    f = node.as_mapping("a light (a mapping with 'type')")
    kind = f.req("type").as_enum(ml.LIGHT_TYPES, "light type")
    C = CLASSES[kind]
    check_keys(f, C, required=("type",) + EXTRA_REQUIRED.get(kind, ()),
               optional=EXTRA_KEYS.get(kind, ()))
    name = f.get("name").as_name("a light name") if "name" in f else default_light_name(index)
    common = dict(name=name, where=node.where, **read_fields(f, C))
    if kind == "directional":
        if not math.sqrt(sum(x * x for x in common["direction_to_light"])) > 0:
            raise f.get("direction_to_light").error("expected a non-zero direction [x, y, z], got [0, 0, 0]")
        return C(**common)
    if kind == "envmap":
        path, written = f.get("path").as_path(ENVMAP_SUFFIXES, "environment image")
        return C(path=path, path_as_written=written, **common)
    if kind == "spot":
        cutoff = common["cutoff_deg"]
        beam = read_float(f, C, "beam_width_deg", default=ml.BEAM_WIDTH_FRACTION * cutoff,
                          hi=cutoff)
        world_from_light = aim(common["position"], common["target"], WORLD_UP, f.get("target"))
        return C(world_from_light=world_from_light, beam_width_deg=beam, **common)
    if kind != "area":
        return C(**common)
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
    return C(world_from_light=world_from_light, **common)
