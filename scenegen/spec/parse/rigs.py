"""``rigs:``: stereo (left, right, baseline, vergence) and multi-camera rigs."""
from __future__ import annotations

import math

from scenegen.geometry.pose import Rigid3
from scenegen.located_yaml import Node
from scenegen.spec.model.cameras import RIG_TYPES, Rig, RigMember
from scenegen.spec.parse.cameras import camera_ref
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.read import read_float
from scenegen.spec.parse.transforms import parse_pose

STEREO_MEMBERS = ("left", "right")


def stereo_rig(name: str, left: str, right: str, baseline_m: float, vergence_deg: float = 0.0,
               where=None) -> Rig:
    """A stereo rig: the left camera at the rig origin, the right one at (+baseline_m, 0, 0), each
    turned by vergence_deg / 2 about its y axis toward the other."""
    half = math.radians(vergence_deg) / 2
    members = (
        RigMember(name="left", camera=left, rig_from_cam=Rigid3.from_rotvec([0.0, half, 0.0], [0.0, 0.0, 0.0])),
        RigMember(name="right", camera=right,
                  rig_from_cam=Rigid3.from_rotvec([0.0, -half, 0.0], [baseline_m, 0.0, 0.0])),
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
        mf = item.as_mapping("a rig member (camera, name, rig_from_cam)")
        mf.check(required=("camera",), optional=("name", "rig_from_cam"))
        cam = camera_ref(mf.get("camera"), ctx.cameras)
        mname = mf.get("name").as_name("a member name") if "name" in mf else cam
        if mname in seen:
            where = mf.get("name") or mf.get("camera")
            raise where.error(f"duplicate member name {mname!r} in rig {name!r} (first at "
                              f"line {seen[mname]}); give each member a distinct 'name'")
        seen[mname] = item.line
        rig_from_cam = (parse_pose(mf.get("rig_from_cam")) if "rig_from_cam" in mf
                        else Rigid3.identity())
        members.append(RigMember(name=mname, camera=cam, rig_from_cam=rig_from_cam))
    if not members:
        raise f.get("members").error("expected at least one rig member, got an empty list")
    return Rig(name=name, type=kind, members=tuple(members), where=node.where)
