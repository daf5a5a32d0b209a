"""``objects:``: geometry (procedural shape, mesh file or calibration target), transform,
material (named or inline), ids and motion."""
from __future__ import annotations

from typing import Mapping

from scenegen.assets.asset_refs import AssetFileError, scan_mesh_file
from scenegen.assets.board_raster import BoardRasterError, layout_of, texels_per_unit
from scenegen.errors import SpecError
from scenegen.geometry.conventions import mesh_up_axis
from scenegen.located_yaml import Fields, Node, suggest
from scenegen.spec.model import geometry as mg
from scenegen.spec.model.materials import DiffuseMaterial, Material
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.materials import parse_material
from scenegen.spec.parse.optics import parse_motion
from scenegen.spec.parse.read import read_bool, read_enum, read_float, read_floats, read_int, seed_or_none
from scenegen.spec.parse.timeline import ANIMATION_KEYS, parse_animation
from scenegen.spec.parse.transforms import parse_transform

#: The keys of each shape type, besides `type`.
SHAPE_KEYS = {
    "plane": ("size",), "box": ("size",), "sphere": ("radius",),
    "cylinder": ("radius", "height"), "torus": ("major_radius", "minor_radius"),
    "blob": ("radius", "amplitude", "frequency", "subdivisions", "seed"),
}
SHAPE_CLASSES = {"plane": mg.Plane, "box": mg.Box, "sphere": mg.Sphere, "cylinder": mg.Cylinder,
                 "torus": mg.Torus, "blob": mg.Blob}


def parse_object(node: Node, index: int, ctx: ParseContext) -> mg.SceneObject:
    f = node.as_mapping("an object (a mapping with 'name' and one of shape, mesh, target)")
    f.check(required=("name",),
            optional=("shape", "mesh", "target", "transform", "material", "instance_id", "motion")
            + ANIMATION_KEYS)
    name = f.get("name").as_name("an object name")
    which = f.one_of(("shape", "mesh", "target"))
    if which == "shape":
        geometry = parse_shape(f.get("shape"), ctx)
    elif which == "mesh":
        geometry = parse_mesh(f.get("mesh"), f.get("material"), ctx)
    else:
        geometry = parse_target(f.get("target"))
    transform = parse_transform(f.get("transform")) if "transform" in f else mg.Transform()
    animation, transform = parse_animation(f, node, transform, ctx)
    material = object_material(f.get("material"), node, ctx.materials, ctx)
    object_id = index + 1
    instance_id = read_int(f, mg.SceneObject, "instance_id", default=object_id)
    return mg.SceneObject(name=name, geometry=geometry, transform=transform, material=material,
                          object_id=object_id, instance_id=instance_id,
                          motion=parse_motion(f.get("motion")) if "motion" in f else None,
                          animation=animation, where=node.where)


def parse_mesh(node: Node, mat_node: Node | None, ctx: ParseContext) -> mg.Mesh:
    """A mesh file, the files it names (each checked: inside the mesh's folder, existing; an
    error names the asset file and line) and whether its own materials are rendered: yes when
    the file has materials and the object gives none; a `material:` replaces them, with a
    warning."""
    up_node = None
    if node.is_mapping:  # `mesh: {path: ..., up_axis: y}`
        f = node.as_mapping("a mesh (a file path, or a mapping with 'path' and 'up_axis')")
        f.check(required=("path",), optional=("up_axis",))
        up_node, node = f.get("up_axis"), f.get("path")
    path, written = node.as_path(mg.MESH_SUFFIXES, "mesh")
    up_axis = mesh_up_axis(path.suffix) if up_node is None else up_node.as_enum(mg.MESH_UP_AXES, "up axis")
    try:
        scan = scan_mesh_file(path)
    except AssetFileError as e:
        raise SpecError(f"{e.message} (the mesh of {node.where})", file=str(e.file),
                        line=e.line) from None
    files = tuple(mg.AssetFile(path=r.path, path_as_written=r.written) for r in scan.refs)
    if scan.has_materials and mat_node is not None:
        what = ", ".join(scan.materials) or "vertex colours"
        ctx.warn(mat_node, f"the mesh {written!r} has its own materials ({what}); this "
                 "`material:` replaces them all (leave it out to render the file's materials)")
    return mg.Mesh(path=path, path_as_written=written, files=files,
                   own_materials=scan.has_materials and mat_node is None, up_axis=up_axis)


def object_material(mat_node: Node | None, node: Node, materials: Mapping[str, Material],
                    ctx: ParseContext) -> Material:
    """A `materials:` name, an inline material, or (absent) the default grey diffuse."""
    if mat_node is None:
        return DiffuseMaterial(where=node.where)
    if mat_node.is_mapping:
        return parse_material(mat_node, None, ctx)
    ref = mat_node.as_str("a material name or an inline material mapping")
    if ref not in materials:
        defined = ", ".join(materials) or "none"
        raise mat_node.error(f"undefined material {ref!r}{suggest(ref, materials)}; "
                             f"defined under materials: {defined}")
    return materials[ref]


def parse_shape(node: Node, ctx: ParseContext) -> mg.Shape:
    if not node.is_mapping:
        kind = node.as_enum(mg.SHAPE_KINDS, "shape")  # shorthand: `shape: sphere`
        f = None
    else:
        f = node.as_mapping()
        kind = f.req("type").as_enum(mg.SHAPE_KINDS, "shape type")
    if f is None:
        f = Fields.empty(node)
    else:
        f.check(required=("type",), optional=SHAPE_KEYS[kind])
    cls = SHAPE_CLASSES[kind]
    if kind in ("plane", "box"):
        return cls(size=read_floats(f, cls, "size", 2 if kind == "plane" else 3))
    if kind == "sphere":
        return cls(radius=read_float(f, cls, "radius"))
    if kind == "cylinder":
        return cls(radius=read_float(f, cls, "radius"), height=read_float(f, cls, "height"))
    if kind == "torus":
        major, minor = read_float(f, cls, "major_radius"), read_float(f, cls, "minor_radius")
        if minor >= major:
            bad = f.get("minor_radius") or f.get("major_radius") or node
            raise bad.error(f"expected minor_radius < major_radius (a ring torus), got "
                            f"minor_radius {minor:g} >= major_radius {major:g}")
        return cls(major_radius=major, minor_radius=minor)
    seed = seed_or_none(f, cls)
    return cls(radius=read_float(f, cls, "radius"), amplitude=read_float(f, cls, "amplitude"),
               frequency=read_float(f, cls, "frequency"),
               subdivisions=read_int(f, cls, "subdivisions"),
               seed=ctx.seed_for(node.path) if seed is None else seed)


def parse_target(node: Node) -> mg.Target:
    """A calibration target, refused (naming the field) when its picture cannot be drawn with every
    edge on a texel boundary within the texture size limit (:mod:`scenegen.assets.board_raster`)."""
    f = node.as_mapping("a calibration target (a mapping with 'type')")
    target = _read_target(f)
    try:
        texels_per_unit(layout_of(target))
    except BoardRasterError as e:
        raise (f.get(e.field) or node).error(str(e)) from None
    return target


def _read_target(f: Fields) -> mg.Target:
    kind = f.req("type").as_enum(mg.TARGET_KINDS, "target type")
    if kind == "checkerboard":
        C = mg.CheckerboardTarget
        f.check(required=("type", "inner_cols", "inner_rows", "square_m"), optional=("margin_m",))
        square = read_float(f, C, "square_m")
        return C(inner_cols=read_int(f, C, "inner_cols"), inner_rows=read_int(f, C, "inner_rows"),
                 square_m=square, margin_m=read_float(f, C, "margin_m", default=square))
    dict_node = f.get("dictionary")
    if kind == "charuco":
        C = mg.CharucoTarget
        f.check(required=("type", "squares_x", "squares_y", "square_m", "marker_m",
                          "dictionary"), optional=("margin_m", "legacy_pattern"))
        sx, sy = read_int(f, C, "squares_x"), read_int(f, C, "squares_y")
        square = read_float(f, C, "square_m")
        marker = read_float(f, C, "marker_m")
        if marker >= square:
            raise f.get("marker_m").error(
                f"expected marker_m < square_m ({square:g}), got {marker:g}")
        dictionary = read_enum(f, C, "dictionary")
        needed = sx * sy // 2
        if needed > mg.ARUCO_DICTIONARIES[dictionary]:
            raise dict_node.error(f"{dictionary} holds {mg.ARUCO_DICTIONARIES[dictionary]} "
                                  f"markers; a {sx}x{sy} ChArUco board needs {needed}")
        return C(squares_x=sx, squares_y=sy, square_m=square, marker_m=marker,
                 dictionary=dictionary, margin_m=read_float(f, C, "margin_m", default=square),
                 legacy_pattern=read_bool(f, C, "legacy_pattern"))
    C = mg.ArucoGridTarget
    f.check(required=("type", "markers_x", "markers_y", "marker_m", "separation_m",
                      "dictionary"), optional=("first_id", "margin_m"))
    mx, my = read_int(f, C, "markers_x"), read_int(f, C, "markers_y")
    sep = read_float(f, C, "separation_m")
    dictionary = read_enum(f, C, "dictionary")
    first = read_int(f, C, "first_id")
    size = mg.ARUCO_DICTIONARIES[dictionary]
    if first + mx * my > size:
        raise dict_node.error(f"{dictionary} holds {size} markers; a {mx}x{my} grid from id "
                              f"{first} needs {first + mx * my}")
    return C(markers_x=mx, markers_y=my, marker_m=read_float(f, C, "marker_m"), separation_m=sep,
             dictionary=dictionary, first_id=first,
             margin_m=read_float(f, C, "margin_m", default=sep))

