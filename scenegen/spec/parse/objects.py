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
from scenegen.spec.parse.annotation import parse_annotation
from scenegen.spec.parse.context import ParseContext
from scenegen.spec.parse.fields import check_keys, read_fields
from scenegen.spec.parse.library import library_model
from scenegen.spec.parse.materials import parse_material
from scenegen.spec.parse.optics import parse_motion
from scenegen.spec.model.meta import field_info
from scenegen.spec.parse.read import read_float, read_int, seed_or_none
from scenegen.spec.parse.timeline import ANIMATION_KEYS, parse_animation
from scenegen.spec.parse.transforms import parse_transform

SHAPE_CLASSES = {"plane": mg.Plane, "box": mg.Box, "sphere": mg.Sphere, "cylinder": mg.Cylinder,
                 "torus": mg.Torus, "blob": mg.Blob}
TARGET_CLASSES = {"checkerboard": mg.CheckerboardTarget, "charuco": mg.CharucoTarget,
                  "aruco_grid": mg.ArucoGridTarget}


def parse_object(node: Node, index: int, ctx: ParseContext) -> mg.SceneObject:
    f = node.as_mapping("an object (a mapping with 'name' and one of shape, mesh, target)")
    f.check(required=("name",),
            optional=("shape", "mesh", "target", "transform", "material", "instance_id", "motion", "annotation")
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
                          animation=animation,
                          annotation=parse_annotation(f.get("annotation"), name) if "annotation" in f else None,
                          where=node.where)


def parse_mesh(node: Node, mat_node: Node | None, ctx: ParseContext) -> mg.Mesh:
    """A mesh file (or an asset library's model, :mod:`.library`), the files it names (each
    checked: inside the mesh's folder -- a library model's folder --, existing; an error names
    the asset file and line) and whether its own materials are rendered: yes when the file has
    materials and the object gives none; a `material:` replaces them, with a warning."""
    up_node = library = within = node_f = None
    if node.is_mapping:  # `mesh: {path: ..., up_axis: y}` or `mesh: {library: ..., root: ..., id: ...}`
        f = node_f = node.as_mapping("a mesh (a file path, or a mapping with 'path' or 'library')")
        up_node = f.get("up_axis")
        if "library" in f:
            lib, library, written, up_default = library_model(f, node, ctx)
            path, within = lib.path, lib.asset_dir
        else:
            f.check(required=("path",), optional=("up_axis", "scale"))
            node = f.get("path")
    if library is None:
        path, written = node.as_path(mg.MESH_SUFFIXES, "mesh")
        up_default = mesh_up_axis(path.suffix)
    up_axis = up_default if up_node is None else up_node.as_enum(mg.MESH_UP_AXES, "up axis")
    scale = read_float(node_f, mg.Mesh, "scale") if node_f is not None else field_info(mg.Mesh, "scale").default
    try:
        scan = scan_mesh_file(path, within)
    except AssetFileError as e:
        raise SpecError(f"{e.message} (the mesh of {node.where})", file=str(e.file),
                        line=e.line) from None
    files = tuple(mg.AssetFile(path=r.path, path_as_written=r.written) for r in scan.refs)
    if scan.has_materials and mat_node is not None:
        what = ", ".join(scan.materials) or "vertex colours"
        ctx.warn(mat_node, f"the mesh {written!r} has its own materials ({what}); this "
                 "`material:` replaces them all (leave it out to render the file's materials)")
    return mg.Mesh(path=path, path_as_written=written, files=files,
                   own_materials=scan.has_materials and mat_node is None, up_axis=up_axis,
                   scale=scale, library=library)


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
        check_keys(f, SHAPE_CLASSES[kind], required=("type",))
    cls = SHAPE_CLASSES[kind]
    values = read_fields(f, cls)
    if kind == "torus" and values["minor_radius"] >= values["major_radius"]:
        bad = f.get("minor_radius") or f.get("major_radius") or node
        raise bad.error(f"expected minor_radius < major_radius (a ring torus), got minor_radius "
                        f"{values['minor_radius']:g} >= major_radius {values['major_radius']:g}")
    if kind == "blob":
        seed = seed_or_none(f, cls)
        values["seed"] = ctx.seed_for(node.path) if seed is None else seed
    return cls(**values)


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
    C = TARGET_CLASSES[kind]
    check_keys(f, C, required=("type",))
    values = read_fields(f, C)
    dict_node = f.get("dictionary")
    if kind == "checkerboard":
        return C(**values, margin_m=read_float(f, C, "margin_m", default=values["square_m"]))
    dictionary = values["dictionary"]
    if kind == "charuco":
        sx, sy, square, marker = (values[k] for k in ("squares_x", "squares_y", "square_m", "marker_m"))
        if marker >= square:
            raise f.get("marker_m").error(
                f"expected marker_m < square_m ({square:g}), got {marker:g}")
        needed = sx * sy // 2
        if needed > mg.ARUCO_DICTIONARIES[dictionary]:
            raise dict_node.error(f"{dictionary} holds {mg.ARUCO_DICTIONARIES[dictionary]} "
                                  f"markers; a {sx}x{sy} ChArUco board needs {needed}")
        return C(**values, margin_m=read_float(f, C, "margin_m", default=square))
    mx, my, first = values["markers_x"], values["markers_y"], values["first_id"]
    size = mg.ARUCO_DICTIONARIES[dictionary]
    if first + mx * my > size:
        raise dict_node.error(f"{dictionary} holds {size} markers; a {mx}x{my} grid from id "
                              f"{first} needs {first + mx * my}")
    return C(**values, margin_m=read_float(f, C, "margin_m", default=values["separation_m"]))
