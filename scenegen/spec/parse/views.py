"""``views:``: view sets, each placing a camera or a rig's frame (orbit, look_at, poses,
random, path), with optional motion and per-view-set lighting."""
from __future__ import annotations

from scenegen.geometry.pose import look_at
from scenegen.located_yaml import Node, suggest
from scenegen.spec.model import views as mv
from scenegen.spec.model.meta import field_info, frozen_mapping
from scenegen.spec.parse.cameras import camera_ref
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import check_keys, read_fields
from scenegen.spec.parse.optics import parse_motion
from scenegen.spec.parse.read import read_vec3, seed_or_none
from scenegen.spec.parse.timeline import parse_trajectory
from scenegen.spec.parse.transforms import parse_pose

PLACEMENTS = ("orbit", "look_at", "poses", "random", "path", "trajectory")


def parse_view_set(node: Node, index: int, ctx: ParseContext) -> mv.ViewSet:
    f = node.as_mapping("a view set (camera or rig, and one of orbit, look_at, poses, "
                        "random, path)")
    f.check(optional=("name", "camera", "rig", "motion", "lights") + PLACEMENTS)
    name = f.get("name").as_name("a view set name") if "name" in f else None
    who = f.one_of(("camera", "rig"))
    camera = rig = None
    if who == "camera":
        camera = camera_ref(f.get("camera"), ctx.cameras)
    else:
        rn = f.get("rig")
        rig = rn.as_str("a rig name")
        if rig not in ctx.rigs:
            defined = ", ".join(ctx.rigs) or "none"
            raise rn.error(f"undefined rig {rig!r}{suggest(rig, ctx.rigs)}; defined under "
                           f"rigs: {defined}")
    kind = f.one_of(PLACEMENTS)
    if (kind == "trajectory") != (ctx.sequence is not None):
        raise f.get(kind).error("a trajectory needs a top-level 'sequence:' section (its clock)"
                                if kind == "trajectory" else "in a sequence every view set follows "
                                "a 'trajectory' (one view per frame of the clock)")
    if kind == "trajectory" and "motion" in f:
        raise f.get("motion").error("'motion' cannot be combined with a trajectory: within the "
                                    "exposure the camera follows the trajectory itself")
    parse = {"orbit": parse_orbit, "look_at": parse_look_at_list, "poses": parse_poses,
             "random": parse_random, "path": parse_path, "trajectory": parse_trajectory_path}[kind]
    placement = parse(f.get(kind), "rig" if rig else "cam", ctx)
    return mv.ViewSet(name=name, camera=camera, rig=rig, placement=placement,
                      motion=parse_motion(f.get("motion")) if "motion" in f else None,
                      lights=parse_view_lights(f.get("lights"), ctx) if "lights" in f else None,
                      where=node.where)


def parse_view_lights(node: Node, ctx: ParseContext):
    """A view set's ``lights``: a list of names (those at their spec power, the others off)
    or a mapping name -> factor >= 0 (unnamed lights off). Returns every spec light, in
    spec order, with its factor."""
    names = [light.name for light in ctx.lights]
    if not names:
        raise node.error("the spec defines no lights (add a 'lights:' section); 'lights' on a "
                         "view set switches and scales the spec's lights")

    def known(name_node: Node, name: str) -> str:
        if name not in names:
            raise name_node.error(f"undefined light {name!r}{suggest(name, names)}; "
                                  f"defined under lights: {', '.join(names)}")
        return name

    meta = field_info(mv.ViewSet, "lights").meta
    given: dict[str, float] = {}
    if node.is_sequence:
        first: dict[str, int | None] = {}
        for item in node.items():
            name = known(item, item.as_str("a light name"))
            if name in first:
                raise item.error(f"duplicate light {name!r} (first at line {first[name]})")
            first[name] = item.line
            given[name] = 1.0
    elif node.is_mapping:
        f = node.as_mapping()
        for name in f.keys():
            known(f.key_node(name), name)
            given[name] = f.value(name).as_float(meta.shown, lo=meta.lo)
    else:
        raise node.error("expected a list of light names (on at their spec power, the others "
                         "off) or a mapping of light names to factors >= 0, got "
                         f"{node.describe()}")
    if not given:
        raise node.error("expected at least one light (an empty list or mapping would turn "
                         "every light off; give {name: 0} to do that on purpose)")
    return frozen_mapping({name: given.get(name, 0.0) for name in names})


def parse_trajectory_path(node: Node, frame: str, ctx: ParseContext) -> mv.TrajectoryPath:
    return mv.TrajectoryPath(trajectory=parse_trajectory(node, frame),
                             times_s=ctx.sequence.timestamps_s)


def parse_orbit(node: Node, frame: str, ctx: ParseContext) -> mv.Orbit:
    O = mv.Orbit
    f = check_keys(node.as_mapping("an orbit (center, radius_m, elevations_deg, count)"), O)
    values = read_fields(f, O)
    if "elevations_deg" in f:
        hi = field_info(O, "elevations_deg").meta.hi
        for item, e in zip(f.get("elevations_deg").items(), values["elevations_deg"]):
            if abs(e) >= hi:
                raise item.error(f"expected an elevation strictly between -90 and 90 degrees "
                                 f"(the view would be parallel to up), got {e:g}")
    return O(**values)


def parse_look_at_list(node: Node, frame: str, ctx: ParseContext) -> mv.LookAtList:
    entries = []
    L = mv.LookAt
    for item in node.items("a list of {eye, target, up} mappings"):
        f = check_keys(item.as_mapping("a mapping with eye, target and optionally up"), L)
        entry = L(**read_fields(f, L))
        try:
            look_at(entry.eye, entry.target, entry.up)
        except ValueError as e:
            raise item.error(f"cannot look from {list(entry.eye)} at {list(entry.target)} "
                             f"with up {list(entry.up)}: {e}") from None
        entries.append(entry)
    if not entries:
        raise node.error("expected at least one {eye, target} entry, got an empty list")
    return mv.LookAtList(entries=tuple(entries))


def parse_poses(node: Node, frame: str, ctx: ParseContext) -> mv.PoseList:
    fwd, inv = f"world_from_{frame}", f"{frame}_from_world"
    other = "rig" if frame == "cam" else "cam"
    out = []
    for item in node.items(f"a list of poses ({fwd} or {inv})"):
        f = item.as_mapping(f"a mapping with {fwd} or {inv}")
        wrong = [k for k in f.keys() if k in (f"world_from_{other}", f"{other}_from_world")]
        if wrong:
            whose = "a rig" if frame == "rig" else "a camera"
            raise f.key_node(wrong[0]).error(f"this view set places {whose}: use {fwd} or {inv}")
        f.check(optional=(fwd, inv))
        key = f.one_of((fwd, inv))
        pose = parse_pose(f.get(key))
        out.append(pose if key == fwd else pose.inverse())
    if not out:
        raise node.error("expected at least one pose, got an empty list")
    return mv.PoseList(world_from_cam=tuple(out))


def parse_random(node: Node, frame: str, ctx: ParseContext) -> mv.RandomPoses:
    f = node.as_mapping("random views (count, eye_box, target or target_box)").check(
        required=("count", "eye_box"),
        optional=("seed", "target", "target_box", "up", "min_distance_m"))
    R = mv.RandomPoses
    eye_min, eye_max = parse_box(f.get("eye_box"))
    which = f.one_of(("target", "target_box"))
    if which == "target":
        t_min = t_max = read_vec3(f, R, "target_min", "target")
    else:
        t_min, t_max = parse_box(f.get("target_box"))
    seed = seed_or_none(f, R)
    return R(**read_fields(f, R), seed=ctx.seed_for(node.path) if seed is None else seed,
             eye_min=eye_min, eye_max=eye_max, target_min=t_min, target_max=t_max)


def parse_box(node: Node):
    """{min: [x, y, z], max: [x, y, z]} with max >= min on every axis, metres."""
    f = node.as_mapping("a box {min: [x, y, z], max: [x, y, z]}").check(required=("min", "max"))
    lo, hi = f.vec3("min"), f.vec3("max")
    if any(a > b for a, b in zip(lo, hi)):
        raise f.get("max").error(f"expected max >= min on every axis, got min {list(lo)} and "
                                 f"max {list(hi)}")
    return lo, hi


def parse_path(node: Node, frame: str, ctx: ParseContext):
    f = node.as_mapping("a path (line or circle, count, target, up)")
    f.check(required=("count",), optional=("line", "circle", "target", "up"))
    which = f.one_of(("line", "circle"))
    if which == "line":
        L = mv.LinePath
        lf = f.get("line").as_mapping("a line {from, to}").check(required=("from", "to"))
        if "target" not in f:
            raise f.missing("target", " (a line path looks at a fixed target)")
        return L(**read_fields(lf, L, within="line"), **read_fields(f, L))
    C = mv.CirclePath
    cf = f.get("circle").as_mapping("a circle {center, radius_m, height_m}").check(
        required=("radius_m",), optional=("center", "height_m", "start_azimuth_deg"))
    circle = read_fields(cf, C, within="circle")
    return C(**circle, **read_fields(f, C),
             target=read_vec3(f, C, "target", default=circle["center"]))
