"""``objects[i].annotation``: the model an object is an instance of, its symmetries, keypoints
and skeleton (:mod:`scenegen.spec.model.annotation`), and the rules across objects (a skeleton
names keypoints of its object and its descendants)."""
from __future__ import annotations

import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.located_yaml import Node
from scenegen.spec.model.annotation import Annotation, ContinuousSymmetry, Keypoint
from scenegen.spec.model.meta import field_info
from scenegen.spec.parse.transforms import POSE_KEYS, parse_rigid

KEYS = ("model", "symmetries", "keypoints", "skeleton")
#: A discrete symmetry must be a rotation of the model onto itself: R orthonormal to this.
_ORTHO_TOL = 1e-9


def parse_annotation(node: Node, object_name: str) -> Annotation:
    f = node.as_mapping("an annotation (a mapping with model, symmetries, keypoints, skeleton)").check(optional=KEYS)
    model = f.get("model").as_name("a model name") if "model" in f else object_name
    discrete, continuous = (), ()
    if "symmetries" in f:
        s = f.get("symmetries").as_mapping("symmetries (a mapping with discrete, continuous)").check(
            optional=("discrete", "continuous"))
        if "discrete" in s:
            discrete = tuple(_discrete(n) for n in s.get("discrete").items("a list of transforms"))
        if "continuous" in s:
            continuous = tuple(_continuous(n) for n in s.get("continuous").items("a list of {axis, offset}"))
    keypoints = ()
    if "keypoints" in f:
        kf = f.get("keypoints").as_mapping("keypoints (a mapping name: [x, y, z] or {vertex: index})")
        keypoints = tuple(_keypoint(kf.key_node(k), kf.get(k)) for k in kf.keys())
    skeleton = ()
    if "skeleton" in f:
        skeleton = tuple(tuple(n.as_name("a keypoint name") for n in _pair(e))
                         for e in f.get("skeleton").items("a list of [keypoint, keypoint] pairs"))
    return Annotation(model=model, symmetries_discrete=discrete, symmetries_continuous=continuous,
                      keypoints=keypoints, skeleton=skeleton)


def _pair(node: Node) -> list[Node]:
    items = node.items("a pair [keypoint, keypoint]")
    if len(items) != 2:
        raise node.error(f"expected a pair [keypoint, keypoint], got {len(items)} entries")
    return items


def _discrete(node: Node) -> Rigid3:
    f = node.as_mapping("a symmetry transform (rotation_deg / rotation_quat_wxyz, translation, or matrix)")
    f.check(optional=POSE_KEYS)
    pose = parse_rigid(f)
    R = pose.R
    if not np.allclose(R @ R.T, np.eye(3), atol=_ORTHO_TOL) or np.linalg.det(R) < 0:
        raise node.error("expected a rotation (orthonormal, determinant +1) in a discrete symmetry")
    return pose


def _continuous(node: Node) -> ContinuousSymmetry:
    f = node.as_mapping("a continuous symmetry {axis: [x, y, z], offset: [x, y, z]}").check(
        required=("axis",), optional=("offset",))
    axis = np.asarray(f.get("axis").as_vec3("direction"), np.float64)
    n = float(np.linalg.norm(axis))
    if n < 1e-12:
        raise f.get("axis").error("expected a non-zero axis direction")
    offset = f.vec3("offset", field_info(ContinuousSymmetry, "offset_m").default)
    return ContinuousSymmetry(axis=tuple(float(x) for x in axis / n), offset_m=tuple(float(x) for x in offset))


def _keypoint(key: Node, node: Node) -> Keypoint:
    name = key.as_name("a keypoint name")
    if node.is_mapping:
        f = node.as_mapping("a keypoint {vertex: index}").check(required=("vertex",))
        return Keypoint(name=name, vertex=f.get("vertex").as_int("vertex index", lo=0))
    return Keypoint(name=name, position_object_m=node.as_vec3("metres, object frame"))


def _same_model(a, b) -> bool:
    """Two instances declare one model alike: geometry, scale, keypoints, symmetries, skeleton."""
    x, y = a.annotation, b.annotation
    same_sym = len(x.symmetries_discrete) == len(y.symmetries_discrete) and all(
        np.array_equal(p.matrix, q.matrix) for p, q in zip(x.symmetries_discrete, y.symmetries_discrete))
    return (a.geometry == b.geometry and tuple(a.transform.scale) == tuple(b.transform.scale) and same_sym
            and (x.keypoints, x.symmetries_continuous, x.skeleton) == (y.keypoints, y.symmetries_continuous, y.skeleton))


def check_annotations(objects, objects_node: Node) -> None:
    """Instances of one model declared alike; keypoint names unique over each annotated tree,
    skeleton pairs naming its keypoints."""
    children: dict[str, list] = {}
    for o in objects:
        parent = getattr(getattr(o, "animation", None), "parent", None)
        children.setdefault(parent, []).append(o)
    nodes = objects_node.items()
    first: dict = {}
    for i, o in enumerate(objects):
        a = o.annotation
        if a is None:
            continue
        ref = first.setdefault(a.model, o)
        if not _same_model(ref, o):
            raise nodes[i].as_mapping().get("annotation").error(
                f"model {a.model!r} is declared by {ref.name!r} with other geometry, scale, keypoints, symmetries "
                f"or skeleton; instances of one model must be alike (a YAML anchor, `annotation: *name`, shares one)")
        names, stack = [], [o]
        while stack:  # this object and its descendants
            x = stack.pop(0)
            if x.annotation is not None:
                names += [k.name for k in x.annotation.keypoints]
            stack += children.get(x.name, [])
        where = nodes[i].as_mapping().get("annotation")
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise where.error(f"keypoint names must be unique over an object and its parts; {dup[0]!r} repeats")
        for pair in a.skeleton:
            for n in pair:
                if n not in names:
                    raise where.error(f"skeleton names keypoint {n!r}, which is not a keypoint of {o.name!r} "
                                      f"or its parts (they have: {', '.join(names) or 'none'})")


def annotation_to_yaml(a: Annotation) -> dict:
    """The inverse of :func:`parse_annotation` (discrete symmetries as bit-exact 4x4 rows)."""
    d: dict = {"model": a.model}
    sym: dict = {}
    if a.symmetries_discrete:
        sym["discrete"] = [{"matrix": [[float(v) for v in row] for row in s.matrix]} for s in a.symmetries_discrete]
    if a.symmetries_continuous:
        sym["continuous"] = [{"axis": list(c.axis), "offset": list(c.offset_m)} for c in a.symmetries_continuous]
    if sym:
        d["symmetries"] = sym
    if a.keypoints:
        d["keypoints"] = {k.name: ({"vertex": k.vertex} if k.vertex is not None else list(k.position_object_m))
                          for k in a.keypoints}
    if a.skeleton:
        d["skeleton"] = [list(p) for p in a.skeleton]
    return d
