"""Poses as written: translation + Euler angles or quaternion, or a 4x4 / 3x4 matrix (as a list
of rows, or under ``matrix:``); object transforms (pose + scale); aiming a light at a point."""
from __future__ import annotations

import numpy as np

from scenegen.geometry.pose import Rigid3, look_at
from scenegen.geometry.rotation import matrix_from_quat_wxyz, rotation_from_euler_deg
from scenegen.located_yaml import Fields, Node
from scenegen.spec.model.geometry import Transform
from scenegen.spec.model.meta import field_info
from scenegen.spec.parse.read import read_floats

#: Euler axis order when `order` is absent: extrinsic x, then y, then z.
DEFAULT_EULER_ORDER = "xyz"
#: Translation when `translation` is absent.
ORIGIN = (0.0, 0.0, 0.0)
POSE_KEYS = ("translation", "rotation_deg", "rotation_quat_wxyz", "order", "matrix")


def parse_transform(node: Node) -> Transform:
    f = node.as_mapping("a transform (translation, rotation_deg or rotation_quat_wxyz, "
                        "order, scale)")
    f.check(optional=POSE_KEYS + ("scale",))
    scale = field_info(Transform, "scale").default
    if "scale" in f:
        s = f.get("scale")
        if s.is_sequence:
            scale = read_floats(f, Transform, "scale", 3)
        else:
            meta = field_info(Transform, "scale").meta
            v = s.as_float(f"{meta.shown}, or 3 numbers", lo=meta.lo, lo_open=meta.lo_open)
            scale = (v, v, v)
    return Transform(world_from_object=parse_rigid(f), scale=scale)


def parse_rigid(f: Fields) -> Rigid3:
    """translation + rotation_deg (with order) | rotation_quat_wxyz, or ``matrix`` (4x4 / 3x4
    rows, bit-exact: what :func:`scenegen.spec.to_yaml.to_yaml` writes), from checked fields."""
    if "matrix" in f:
        others = [k for k in POSE_KEYS if k != "matrix" and k in f]
        if others:
            raise f.get(others[0]).error(f"give either 'matrix' or {others[0]!r}, not both")
        return matrix_pose(f.get("matrix"))
    t = f.vec3("translation", ORIGIN)
    which = f.one_of(("rotation_deg", "rotation_quat_wxyz"), required=False)
    if "order" in f and which != "rotation_deg":
        raise f.get("order").error("'order' applies to rotation_deg only")
    R = np.eye(3)
    if which == "rotation_deg":
        angles = f.get("rotation_deg").as_floats(3, "degrees")
        R = rotation_from_euler_deg(angles, parse_euler_order(f.get("order")))
    elif which == "rotation_quat_wxyz":
        qn = f.get("rotation_quat_wxyz")
        q = qn.as_floats(4, "quaternion w, x, y, z")
        if np.linalg.norm(q) < 1e-12:
            raise qn.error("expected a non-zero quaternion (w, x, y, z), got all zeros")
        R = matrix_from_quat_wxyz(q)
    return Rigid3(R, t)


def parse_euler_order(node: Node | None) -> str:
    if node is None:
        return DEFAULT_EULER_ORDER
    order = node.as_str("an Euler axis order such as 'xyz'")
    ok = (len(order) == 3 and (set(order) <= set("xyz") or set(order) <= set("XYZ"))
          and order[0] != order[1] and order[1] != order[2])
    if not ok:
        raise node.error("expected 3 axes, all lower case (extrinsic, fixed world axes) or all "
                         f"upper case (intrinsic), no axis twice in a row, e.g. 'xyz' or 'ZYX'; "
                         f"got {order!r}")
    return order


def parse_pose(node: Node) -> Rigid3:
    """A pose given as a 4x4 / 3x4 matrix or as translation + rotation."""
    if node.is_sequence:
        return matrix_pose(node)
    f = node.as_mapping("a pose: a 4x4 matrix, or a mapping with translation and "
                        "rotation_deg or rotation_quat_wxyz")
    f.check(optional=POSE_KEYS)
    return parse_rigid(f)


def matrix_pose(node: Node) -> Rigid3:
    """A rigid 4x4 (or 3x4) matrix given as a list of rows."""
    rows = node.items("a 4x4 (or 3x4) matrix as a list of rows")
    if len(rows) not in (3, 4):
        raise node.error(f"expected a 4x4 (or 3x4) matrix as a list of rows, got "
                         f"{len(rows)} rows")
    T = np.array([r.as_floats(4) for r in rows])
    try:
        return Rigid3.from_matrix(T)
    except ValueError as e:
        raise node.error(f"expected a rigid transform: {e}") from None


def aim(position, target, up, node: Node) -> Rigid3:
    """world_from_light with +z from position toward target; another up (+y) if up is parallel."""
    try:
        return look_at(position, target, up)
    except ValueError as e:
        if "parallel" not in str(e):
            raise node.error(f"expected a point different from the position: {e}") from None
    return look_at(position, target, (0.0, 1.0, 0.0))
