"""The optional top-level ``variation:`` section: seeded ranges that make scene variants.

What is declared here is only ranges; :func:`scenegen.spec.variants.derive_variant` draws one
variant's values from ``(spec, seed, index)``. Every range is validated at load time against
the objects, lights and cameras it names, so that a bad range fails with file, line and field
before anything renders. Nothing here imports Mitsuba. Documented in ``docs/scene_spec.md``.

YAML::

    variation:
      seed: 7                                    # default: derived from the scene seed
      objects:
        rock: {position: {min: [-0.5, -0.5, 0.3], max: [0.5, 0.5, 0.3]}, yaw_deg: [0, 360],
               color: {min: [0.2, 0.2, 0.2], max: [0.9, 0.9, 0.9]}, reseed: true}
      lights:
        light0: {intensity_scale: [0.5, 2.0], position_jitter_m: 0.2}
      cameras:
        cam: {focal_scale: [0.95, 1.05], principal_point_px: 2.0, dist_jitter: [0.02, 0.005, 0, 0]}
      views: {translation_m: 0.05, rotation_deg: 2.0}
"""
from __future__ import annotations

from dataclasses import dataclass, field

from scenegen.errors import Where
from scenegen.spec import model as m
from scenegen.located_yaml import Node, suggest

_WHERE = dict(default=None, compare=False, repr=False)
_SEED_MAX = 2**32 - 1


@dataclass(frozen=True, kw_only=True)
class ObjectVariation:
    object: str  # name of an object in `objects:`
    position_min: tuple[float, float, float] | None = None  # box of the object origin, metres,
    position_max: tuple[float, float, float] | None = None  # world (replaces its translation)
    yaw_deg: tuple[float, float] | None = None  # turn about world +z through the origin, degrees
    color_min: tuple[float, float, float] | None = None  # linear RGB box of the material colour
    color_max: tuple[float, float, float] | None = None  # (diffuse/plastic with a colour only)
    reseed: bool = False  # redraw the seeds of its procedural texture and blob shape
    where: Where | None = field(**_WHERE)


@dataclass(frozen=True, kw_only=True)
class LightVariation:
    light: str  # name of a light in `lights:`
    intensity_scale: tuple[float, float] | None = None  # factor on radiance/intensity/scale
    position_jitter_m: float = 0.0  # uniform offset in [-j, j] per world axis (area/point/spot)
    where: Where | None = field(**_WHERE)


@dataclass(frozen=True, kw_only=True)
class CameraVariation:
    camera: str  # name of a camera in `cameras:`
    focal_scale: tuple[float, float] | None = None  # one factor on fx and fy (unitless, > 0)
    principal_point_px: float = 0.0  # uniform offset in [-j, j] on cx and on cy, pixels
    dist_jitter: tuple[float, ...] = ()  # uniform offset in [-j_i, j_i] per coefficient (OpenCV
    # order); as many values as the camera's `dist`
    where: Where | None = field(**_WHERE)


@dataclass(frozen=True, kw_only=True)
class PoseJitter:
    """A rigid offset per placement (camera, or rig frame), in its own frame: uniform translation
    in [-t, t] per axis and a rotation about a uniform random axis by an angle uniform in [0, r]."""

    translation_m: float = 0.0  # metres
    rotation_deg: float = 0.0  # degrees
    where: Where | None = field(**_WHERE)


@dataclass(frozen=True, kw_only=True)
class VariationSpec:
    seed: int  # explicit, or derived from the scene seed (field path 'variation')
    objects: tuple[ObjectVariation, ...] = ()
    lights: tuple[LightVariation, ...] = ()
    cameras: tuple[CameraVariation, ...] = ()
    views: PoseJitter | None = None
    where: Where | None = field(**_WHERE)


def _range(node: Node, unit: str, *, lo: float | None = None, lo_open: bool = False) -> tuple[float, float]:
    a, b = node.as_floats(2, f"min and max, {unit}", lo=lo, lo_open=lo_open)
    if a > b:
        raise node.error(f"expected min <= max, got [{a:g}, {b:g}]")
    return (a, b)


def _box(node: Node, unit: str, lo: float | None = None, hi: float | None = None):
    f = node.as_mapping(f"a box {{min: [x, y, z], max: [x, y, z]}} ({unit})").check(required=("min", "max"))
    a = f.get("min").as_floats(3, unit, lo=lo, hi=hi)
    b = f.get("max").as_floats(3, unit, lo=lo, hi=hi)
    if any(x > y for x, y in zip(a, b)):
        raise f.get("max").error(f"expected max >= min on every axis, got min {list(a)}, max {list(b)}")
    return a, b


def _named(section: Node, names: list[str], what: str):
    """(name, Fields) per entry of a mapping keyed by names of ``what``s that exist."""
    f = section.as_mapping(f"a mapping of {what} names to their variation")
    for name in f.keys():
        if name not in names:
            raise f.key_node(name).error(f"undefined {what} {name!r}{suggest(name, names)}; "
                                         f"{what}s: {', '.join(names) or 'none'}")
        yield name, f.value(name)


def parse_variation(node: Node, *, scene_seed: int, objects, lights, cameras, derive_seed) -> VariationSpec:
    """Parse and validate the ``variation:`` section against the parsed scene."""
    f = node.as_mapping("a variation section (seed, objects, lights, cameras, views)")
    f.check(optional=("seed", "objects", "lights", "cameras", "views"))
    seed = f.int("seed", None, lo=0, hi=_SEED_MAX)
    seed = derive_seed(scene_seed, "variation") if seed is None else seed
    by_obj = {o.name: o for o in objects}
    by_light = {li.name: li for li in lights}

    objs = []
    if "objects" in f:
        for name, vn in _named(f.get("objects"), list(by_obj), "object"):
            of = vn.as_mapping("an object variation (position, yaw_deg, color, reseed)")
            of.check(optional=("position", "yaw_deg", "color", "reseed"))
            obj = by_obj[name]
            pos = _box(of.get("position"), "metres") if "position" in of else (None, None)
            col = (None, None)
            if "color" in of:
                mat = obj.material
                if not isinstance(mat, (m.DiffuseMaterial, m.PlasticMaterial)) or mat.color is None:
                    raise of.get("color").error(
                        f"object {name!r} has a {mat.type} material"
                        f"{' with a texture' if getattr(mat, 'texture', None) else ''}; colour variation "
                        "needs a diffuse or plastic material with a colour")
                col = _box(of.get("color"), "linear RGB", lo=0.0, hi=1.0)
            reseed = of.get("reseed").as_bool() if "reseed" in of else False
            if reseed:
                tex = getattr(obj.material, "texture", None)
                procedural = tex is not None and tex.kind in m.PROCEDURAL_TEXTURE_KINDS
                if not procedural and not isinstance(obj.geometry, m.Blob):
                    raise of.get("reseed").error(
                        f"object {name!r} has neither a procedural texture nor a blob shape: nothing to reseed")
            objs.append(ObjectVariation(
                object=name, position_min=pos[0], position_max=pos[1],
                yaw_deg=_range(of.get("yaw_deg"), "degrees") if "yaw_deg" in of else None,
                color_min=col[0], color_max=col[1], reseed=reseed, where=vn.where))

    lts = []
    if "lights" in f:
        for name, vn in _named(f.get("lights"), list(by_light), "light"):
            lf = vn.as_mapping("a light variation (intensity_scale, position_jitter_m)")
            lf.check(optional=("intensity_scale", "position_jitter_m"))
            jitter = lf.float("position_jitter_m", 0.0, "metres", lo=0.0)
            light = by_light[name]
            if jitter > 0 and not isinstance(light, (m.AreaLight, m.PointLight, m.SpotLight)):
                raise lf.get("position_jitter_m").error(
                    f"light {name!r} is a {light.type} light, which has no position")
            scale = (_range(lf.get("intensity_scale"), "factor", lo=0.0)
                     if "intensity_scale" in lf else None)
            lts.append(LightVariation(light=name, intensity_scale=scale, position_jitter_m=jitter,
                                      where=vn.where))

    cams = []
    if "cameras" in f:
        for name, vn in _named(f.get("cameras"), list(cameras), "camera"):
            cf = vn.as_mapping("a camera variation (focal_scale, principal_point_px, dist_jitter)")
            cf.check(optional=("focal_scale", "principal_point_px", "dist_jitter"))
            cam = cameras[name]
            dist = ()
            if "dist_jitter" in cf:
                n = len(cam.dist)
                if n == 0:
                    raise cf.get("dist_jitter").error(
                        f"camera {name!r} ({cam.model}) has no distortion coefficients to vary")
                dist = cf.get("dist_jitter").as_floats(n, f"one half-width per coefficient of {name!r}'s dist",
                                                       lo=0.0)
            cams.append(CameraVariation(
                camera=name,
                focal_scale=(_range(cf.get("focal_scale"), "factor", lo=0.0, lo_open=True)
                             if "focal_scale" in cf else None),
                principal_point_px=cf.float("principal_point_px", 0.0, "pixels", lo=0.0),
                dist_jitter=dist, where=vn.where))

    views = None
    if "views" in f:
        vf = f.get("views").as_mapping("a pose jitter (translation_m, rotation_deg)")
        vf.check(optional=("translation_m", "rotation_deg"))
        views = PoseJitter(translation_m=vf.float("translation_m", 0.0, "metres", lo=0.0),
                           rotation_deg=vf.float("rotation_deg", 0.0, "degrees", lo=0.0, hi=180.0),
                           where=f.get("views").where)
    return VariationSpec(seed=seed, objects=tuple(objs), lights=tuple(lts), cameras=tuple(cams),
                         views=views, where=node.where)
