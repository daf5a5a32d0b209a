"""``sequence:`` (the clock, flow steps, point tracks) and the time-dependent parts of objects and
view sets: keyframed trajectories, joints, parents, visible intervals (docs/scene_spec.md,
"Sequences")."""
from __future__ import annotations

import math

import numpy as np

from scenegen.geometry.pose import look_at
from scenegen.located_yaml import Fields, Node, suggest
from scenegen.spec.model import timeline as mt
from scenegen.spec.model.geometry import Transform
from scenegen.spec.model.meta import WORLD_UP
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_enum, read_float, read_floats, read_int, read_vec3, seed_or_none
from scenegen.spec.parse.transforms import POSE_KEYS, parse_pose, parse_rigid
from scenegen.spec.timeline import local_trajectory, object_states
from scenegen.spec.views import resolve_views

ANIMATION_KEYS = ("trajectory", "parent", "joint", "visible_s")
#: Largest accepted frame count of a sequence (its views are named with the frame number).
MAX_FRAMES = 1_000_000


def parse_sequence(node: Node, ctx: ParseContext) -> mt.SequenceSpec:
    f = node.as_mapping("a sequence (fps and frames, or timestamps_s)").check(
        optional=("fps", "frames", "start_s", "timestamps_s", "flow_steps", "tracks"))
    S = mt.SequenceSpec
    which = f.one_of(("fps", "timestamps_s"))
    if which == "fps":
        if "frames" not in f:
            raise f.missing("frames", " (with fps: how many frames)")
        fps, n, start = read_float(f, S, "fps"), read_int(f, S, "frames"), read_float(f, S, "start_s")
        if n > MAX_FRAMES:
            raise f.get("frames").error(f"expected at most {MAX_FRAMES} frames, got {n}")
        times = tuple(start + k / fps for k in range(n))
    else:
        for key in ("frames", "start_s"):
            if key in f:
                raise f.get(key).error(f"{key!r} goes with fps; timestamps_s lists every frame")
        fps = n = None
        start = read_float(f, S, "start_s")
        times = read_floats(f, S, "timestamps_s", None)
        if not times:
            raise f.get("timestamps_s").error("expected at least one timestamp")
        items = f.get("timestamps_s").items()
        for k in range(1, len(times)):
            if times[k] <= times[k - 1]:
                raise items[k].error(f"expected strictly increasing timestamps, got {times[k]:g} "
                                     f"after {times[k - 1]:g}")
    if "flow_steps" not in f:  # the default steps that pair frames (none for a single frame)
        steps = tuple(s for s in read_floats(f, S, "flow_steps", None) if s < len(times))
    elif f.get("flow_steps").items("a list of frame steps") == []:  # no flow asked for
        steps = ()
    else:
        steps = tuple(_whole(f.get("flow_steps"), s) for s in read_floats(f, S, "flow_steps", None))
    for k, step in enumerate(steps):  # a step of the frame count or more pairs no frames
        if step >= len(times):
            raise f.get("flow_steps").items()[k].error(
                f"expected a step below {len(times)} (the sequence's frames), got {step}: no frame pair "
                f"(k, k + {step}) exists")
    tracks = parse_tracks(f.get("tracks"), len(times), ctx) if "tracks" in f else None
    return S(fps=fps, frames=n, start_s=start, timestamps_s=times, flow_steps=steps, tracks=tracks,
             where=node.where)


def _whole(node: Node, x: float) -> int:
    if x != int(x):
        raise node.error(f"expected whole numbers of frames, got {x:g}")
    return int(x)


def parse_tracks(node: Node, n_frames: int, ctx: ParseContext) -> mt.TrackSpec:
    f = node.as_mapping("point tracks (count, query_frames, seed)").check(
        optional=("count", "query_frames", "seed"))
    T = mt.TrackSpec
    q = tuple(_whole(f.get("query_frames"), x) for x in read_floats(f, T, "query_frames", None))
    for k, x in enumerate(q):
        if x >= n_frames:
            raise (f.get("query_frames").items()[k] if "query_frames" in f else node).error(
                f"expected a frame index below {n_frames} (the sequence's frames), got {x}")
    seed = seed_or_none(f, T)
    count = read_int(f, T, "count")
    pixels = max((c.width * c.height for c in ctx.cameras.values()), default=0)
    if "count" in f and pixels and count > len(q) * pixels:  # each query point: a distinct pixel of its frame
        raise f.get("count").error(f"expected at most {len(q) * pixels:,} query points: each is a distinct pixel "
                                   f"of one of {len(q)} query frame(s) of at most {pixels:,} pixels, got {count:,}")
    return T(count=count, query_frames=q,
             seed=ctx.seed_for(node.path) if seed is None else seed, where=node.where)


def parse_trajectory(node: Node, frame: str) -> mt.TrajectorySpec:
    """Keyframes of ``world_from_<frame>`` (frame cam / rig: a pose or eye/target/up per
    keyframe; frame object: translation + rotation, or a pose matrix under ``pose``)."""
    f = node.as_mapping("a trajectory (interpolation, keyframes)").check(
        required=("keyframes",), optional=("interpolation",))
    interp = read_enum(f, mt.TrajectorySpec, "interpolation")
    keys = []
    items = f.get("keyframes").items("a list of keyframes")
    if not items:
        raise f.get("keyframes").error("expected at least one keyframe")
    for item in items:
        kf = item.as_mapping("a keyframe (time_s and a pose)")
        t = read_float(kf, mt.Keyframe, "time_s")
        if keys and t <= keys[-1].time_s:
            raise kf.get("time_s").error(f"expected keyframe times strictly increasing, got "
                                         f"{t:g} after {keys[-1].time_s:g}")
        keys.append(mt.Keyframe(time_s=t, pose=_keyframe_pose(kf, item, frame)))
    return mt.TrajectorySpec(interpolation=interp, keyframes=tuple(keys), where=node.where)


def _keyframe_pose(kf: Fields, item: Node, frame: str):
    if frame == "object":
        kf.check(required=("time_s",), optional=POSE_KEYS + ("pose",))
        if "pose" in kf:
            if any(k in kf for k in POSE_KEYS):
                raise kf.get("pose").error("give either pose or translation/rotation, not both")
            return parse_pose(kf.get("pose"))
        return parse_rigid(kf)
    fwd, inv = f"world_from_{frame}", f"{frame}_from_world"
    kf.check(required=("time_s",), optional=(fwd, inv, "eye", "target", "up"))
    which = kf.one_of((fwd, inv, "eye"))
    if which == "eye":
        if "target" not in kf:
            raise kf.missing("target", " (a look-at keyframe)")
        eye, target, up = kf.vec3("eye"), kf.vec3("target"), kf.vec3("up", WORLD_UP, "direction")
        try:
            return look_at(eye, target, up)
        except ValueError as e:
            raise item.error(f"cannot look from {list(eye)} at {list(target)}: {e}") from None
    for k in ("target", "up"):
        if k in kf:
            raise kf.get(k).error(f"{k!r} goes with eye (a look-at keyframe)")
    pose = parse_pose(kf.get(which))
    return pose if which == fwd else pose.inverse()


def parse_joint(node: Node) -> mt.JointSpec:
    f = node.as_mapping("a joint (type, axis, origin, keyframes)").check(
        required=("type", "axis", "keyframes"), optional=("origin", "interpolation"))
    J = mt.JointSpec
    kind = read_enum(f, J, "type")
    axis = read_vec3(f, J, "axis")
    if np.linalg.norm(axis) == 0:
        raise f.get("axis").error("expected a non-zero axis")
    key = "angle_deg" if kind == "revolute" else "offset_m"
    keys = []
    for item in f.get("keyframes").items("a list of {time_s, " + key + "}"):
        kf = item.as_mapping("a joint keyframe").check(required=("time_s", key))
        t = read_float(kf, mt.JointKeyframe, "time_s")
        if keys and t <= keys[-1].time_s:
            raise kf.get("time_s").error(f"expected keyframe times strictly increasing, got "
                                         f"{t:g} after {keys[-1].time_s:g}")
        v = kf.get(key).as_float("degrees" if kind == "revolute" else "metres")
        keys.append(mt.JointKeyframe(time_s=t, value=math.radians(v) if kind == "revolute" else v))
    if not keys:
        raise f.get("keyframes").error("expected at least one keyframe")
    return J(type=kind, axis=axis, origin=read_vec3(f, J, "origin"),
             interpolation=read_enum(f, J, "interpolation"), keyframes=tuple(keys), where=node.where)


def parse_animation(f: Fields, node: Node, transform: Transform, ctx: ParseContext):
    """(Animation or None, the resolved transform: the object's pose at frame 0 with its scale)."""
    present = [k for k in ANIMATION_KEYS if k in f]
    if not present:
        return None, transform
    if ctx.sequence is None:
        raise f.get(present[0]).error(f"{present[0]!r} needs a top-level 'sequence:' section "
                                      "(the clock it runs on)")
    if "motion" in f:
        raise f.get("motion").error("'motion' (constant velocities within one exposure) cannot be "
                                    f"combined with {present[0]!r}: the sequence's trajectory "
                                    "moves the object, also within the exposure")
    which = f.one_of(("trajectory", "joint"), required=False)
    rest = transform.world_from_object
    if which == "trajectory" and "transform" in f and not rest.allclose(rest.identity(), 0.0):
        raise f.get("transform").error("with a trajectory the keyframes place the object: "
                                           "'transform' may give only 'scale'")
    parent = None
    if "parent" in f:
        pn = f.get("parent")
        parent = pn.as_str("an object name")
        names = [o.name for o in ctx.objects]
        if parent not in names:
            raise pn.error(f"undefined parent {parent!r}{suggest(parent, names)}; a parent must come "
                           f"earlier in objects: ({', '.join(names) or 'none yet'})")
    visible = None
    if "visible_s" in f:
        if node.as_mapping().get("shape") is not None and _is_sphere(node.as_mapping().get("shape")):
            raise f.get("visible_s").error("an analytic sphere cannot leave the scene; use a blob "
                                           "shape with amplitude 0 (a sphere mesh) for an object "
                                           "that appears or leaves")
        visible = read_floats(f, mt.Animation, "visible_s", 2)
        if visible[1] < visible[0]:
            raise f.get("visible_s").error(f"expected [appears, leaves] with appears <= leaves, "
                                           f"got {list(visible)}")
    anim = mt.Animation(
        parent=parent, rest=rest,
        trajectory=parse_trajectory(f.get("trajectory"), "object") if which == "trajectory" else None,
        joint=parse_joint(f.get("joint")) if which == "joint" else None, visible_s=visible)
    return anim, start_transform(anim, transform.scale, ctx.objects, ctx.sequence)


def start_transform(anim: mt.Animation, scale, objects, sequence: mt.SequenceSpec) -> Transform:
    """An animated object's resolved ``transform``: its world pose at frame 0 (through its parent,
    one of ``objects``, the objects before it) with its ``scale``."""
    t0 = sequence.timestamps_s[0]
    pose = local_trajectory(anim).state(t0).world_from_frame  # parent_from_object at frame 0
    if anim.parent is not None:
        pose = object_states(objects, t0)[anim.parent].world_from_object @ pose
    return Transform(world_from_object=pose, scale=scale)


def _is_sphere(shape: Node) -> bool:
    if shape.is_mapping:
        t = shape.as_mapping().get("type")
        return t is not None and t.scalar() == "sphere"
    return shape.scalar() == "sphere"


def check_sequence(f: Fields, spec) -> None:
    """Whole-spec rules of a sequence: the static cross-view truth only without moving objects."""
    moving = [o.name for o in spec.objects if o.animation is not None]
    cv = spec.crossview
    if cv is None or not moving:
        return
    hint = (f"objects {', '.join(moving)} move, and the cross-view truth relates views of one time "
            "only (a rig's members, stereo frames, per-view boards); across time use the "
            "sequence's flow and tracks (sequence.flow_steps, sequence.tracks)")
    node = f.get("crossview")
    cf = node.as_mapping() if node.is_mapping else None
    if cv.flow:
        raise (cf.get("flow") if cf is not None and cf.get("flow") is not None else node).error(
            f"set flow: false: {hint}")
    if isinstance(cv.pairs, str):
        if cv.pairs != "none":
            raise (cf.get("pairs") if cf is not None and cf.get("pairs") is not None else node).error(
                f"pairs {cv.pairs!r} relates frames of different times; give pairs: none or pairs of "
                f"the same frame: {hint}")
        return
    times = {v.name: v.time_s for v in resolve_views(spec)}
    for k, (a, b) in enumerate(cv.pairs):
        if times[a] != times[b]:
            raise cf.get("pairs").items()[k].error(
                f"views {a} and {b} are at {times[a]:g} s and {times[b]:g} s: {hint}")
