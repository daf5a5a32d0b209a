"""``rigs:``: stereo (left, right, baseline, vergence) and multi rigs, whose members are sensors of
the kinds of :data:`scenegen.spec.sensors.SENSOR_KINDS` (a camera unless ``kind`` says otherwise)."""
from __future__ import annotations

import math

from scenegen.geometry.pose import Rigid3
from scenegen.located_yaml import Fields, Node, suggest
from scenegen.spec.model.cameras import RIG_TYPES, Rig, RigMember
from scenegen.spec.model.meta import field_info
from scenegen.spec.parse.cameras import camera_ref
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_float
from scenegen.spec.parse.transforms import parse_pose
from scenegen.spec.sensors import LIGHT, MEMBER_KEYS, SENSOR_KINDS, SensorKind

STEREO_MEMBERS = ("left", "right")


def stereo_rig(name: str, left: str, right: str, baseline_m: float, vergence_deg: float = 0.0,
               where=None) -> Rig:
    """A stereo rig: the left camera at the rig origin, the right one at (+baseline_m, 0, 0), each
    turned by vergence_deg / 2 about its y axis toward the other."""
    half = math.radians(vergence_deg) / 2
    members = (
        RigMember(name="left", sensor=left, rig_from_sensor=Rigid3.from_rotvec([0.0, half, 0.0], [0.0, 0.0, 0.0])),
        RigMember(name="right", sensor=right,
                  rig_from_sensor=Rigid3.from_rotvec([0.0, -half, 0.0], [baseline_m, 0.0, 0.0])),
    )
    return Rig(name=name, type="stereo", members=members, baseline_m=baseline_m, vergence_deg=vergence_deg,
               where=where)


def parse_rig(node: Node, name: str, ctx: ParseContext) -> Rig:
    f = node.as_mapping("a rig (a mapping with 'type': stereo or multi)")
    kind = f.req("type").as_enum(RIG_TYPES, "rig type")
    if kind == "stereo":
        f.check(required=("type",) + STEREO_MEMBERS + ("baseline_m",), optional=("vergence_deg",))
        left, right = (camera_ref(f.get(k), ctx.cameras) for k in STEREO_MEMBERS)
        baseline = read_float(f, Rig, "baseline_m")
        vergence = read_float(f, Rig, "vergence_deg")
        return stereo_rig(name, left, right, baseline, vergence, where=node.where)
    f.check(required=("type", "members"))
    members, seen = [], {}
    for item in f.get("members").items("a list of rig members"):
        member, mf = parse_member(item, ctx)
        if member.name in seen:
            where = mf.get("name") or mf.get(member_sensor_key(mf, SENSOR_KINDS[member.kind]))
            raise where.error(f"duplicate member name {member.name!r} in rig {name!r} (first at "
                              f"line {seen[member.name]}); give each member a distinct 'name'")
        seen[member.name] = item.line
        lights = [mb for mb in members if SENSOR_KINDS[mb.kind].produces == LIGHT]
        if SENSOR_KINDS[member.kind].produces == LIGHT and lights:
            raise item.error(f"rig {name!r} holds the {lights[0].kind} {lights[0].name!r} already; its views are "
                             "lit by one at most")
        members.append(member)
    if not members:
        raise f.get("members").error("expected at least one rig member, got an empty list")
    return Rig(name=name, type=kind, members=tuple(members), where=node.where)


def member_sensor_key(mf: Fields, kind: SensorKind) -> str:
    """The key naming the member's sensor: ``sensor`` or the kind's own (``camera``), one of them."""
    return mf.one_of(tuple(dict.fromkeys((MEMBER_KEYS[0], kind.member_keys[0]))))


def parse_member(item: Node, ctx: ParseContext) -> tuple[RigMember, Fields]:
    """One member of a multi rig: ``{kind (default camera), sensor | camera: NAME, name,
    rig_from_sensor | rig_from_cam: POSE, time_offset_s}``."""
    mf = item.as_mapping("a rig member (kind, sensor or camera, name, rig_from_sensor, time_offset_s)")
    kind_name = (mf.get("kind").as_enum(tuple(SENSOR_KINDS), "sensor kind") if "kind" in mf
                 else field_info(RigMember, "kind").default)
    kind = SENSOR_KINDS[kind_name]
    sensor_keys = tuple(dict.fromkeys((MEMBER_KEYS[0], kind.member_keys[0])))
    pose_keys = tuple(dict.fromkeys((MEMBER_KEYS[1], kind.member_keys[1])))
    mf.check(optional=("kind",) + sensor_keys + ("name",) + pose_keys + ("time_offset_s",))
    ref_node = mf.get(member_sensor_key(mf, kind))
    sensors = kind.sensors_of(ctx)
    ref = ref_node.as_str(f"a {kind.name} name")
    if ref not in sensors:
        raise ref_node.error(f"undefined {kind.name} {ref!r}{suggest(ref, sensors)}; defined under "
                             f"{kind.section}: {', '.join(sensors) or 'none'}")
    mname = mf.get("name").as_name("a member name") if "name" in mf else ref
    pose_key = mf.one_of(pose_keys, required=False)
    rig_from_sensor = parse_pose(mf.get(pose_key)) if pose_key is not None else Rigid3.identity()
    offset = read_float(mf, RigMember, "time_offset_s")
    if offset != 0.0 and not kind.time_offsets:
        raise mf.get("time_offset_s").error(
            f"a {kind.name} member samples at its rig's time (time_offset_s 0); got {offset:g} s")
    return RigMember(name=mname, sensor=ref, rig_from_sensor=rig_from_sensor, kind=kind_name,
                     time_offset_s=offset), mf
