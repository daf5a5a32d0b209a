"""Objects: procedural shapes (all centred on the object origin), meshes, calibration targets,
their placement (transform) and the object record."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np

from scenegen.assets.libraries import LIBRARY_LAYOUTS
from scenegen.errors import Where
from scenegen.geometry.pose import Rigid3
from scenegen.spec.model.materials import Material
from scenegen.spec.model.meta import ID_MAX, SEED_MAX, param, part, where_field
from scenegen.spec.model.limits import MAX_BOARD_SIDE

SHAPE_KINDS = ("plane", "box", "sphere", "cylinder", "torus", "blob")
MESH_SUFFIXES = (".ply", ".obj", ".glb", ".gltf", ".stl")
MESH_UP_AXES = ("z", "y")
TARGET_KINDS = ("checkerboard", "charuco", "aruco_grid")
#: cv2.aruco predefined dictionaries and how many markers each holds.
ARUCO_DICTIONARIES = {
    **{f"DICT_{b}X{b}_{n}": n for b in (4, 5, 6, 7) for n in (50, 100, 250, 1000)},
    "DICT_ARUCO_ORIGINAL": 1024,
    "DICT_APRILTAG_16h5": 30,
    "DICT_APRILTAG_25h9": 35,
    "DICT_APRILTAG_36h10": 2320,
    "DICT_APRILTAG_36h11": 587,
    "DICT_ARUCO_MIP_36h12": 250,
}
_POS_M = dict(unit="metres", lo=0.0, lo_open=True)


@dataclass(frozen=True, kw_only=True)
class Plane:
    size: tuple[float, float] = param((1.0, 1.0), **_POS_M)  # along object x and y; lies in
    # z = 0, normal +z
    kind: str = field(default="plane", init=False)


@dataclass(frozen=True, kw_only=True)
class Box:
    size: tuple[float, float, float] = param((1.0, 1.0, 1.0), **_POS_M)  # full edge lengths
    # (x, y, z)
    kind: str = field(default="box", init=False)


@dataclass(frozen=True, kw_only=True)
class Sphere:
    radius: float = param(0.5, **_POS_M)
    kind: str = field(default="sphere", init=False)


@dataclass(frozen=True, kw_only=True)
class Cylinder:
    radius: float = param(0.5, **_POS_M)
    height: float = param(1.0, **_POS_M)  # along object z, from -height/2 to +height/2 (closed
    # by caps)
    kind: str = field(default="cylinder", init=False)


@dataclass(frozen=True, kw_only=True)
class Torus:
    major_radius: float = param(0.5, **_POS_M)  # centre of the tube to the z axis; in xy
    minor_radius: float = param(0.15, **_POS_M)  # tube radius (< major_radius)
    kind: str = field(default="torus", init=False)


@dataclass(frozen=True, kw_only=True)
class Blob:
    radius: float = param(0.5, **_POS_M)  # radius of the undisplaced sphere
    amplitude: float = param(0.15, unit="fraction of radius", lo=0.0, hi=1.0, hi_open=True)
    # radial displacement
    frequency: float = param(2.0, unit="noise cycles per unit length", label="", lo=0.0,
                             lo_open=True)  # on the unit sphere
    subdivisions: int = param(5, unit="icosphere level", label="", lo=1, hi=7)  # 20 * 4**n
    # triangles
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX,
                      derived="seed32(scene seed, field path)")  # noise seed
    kind: str = field(default="blob", init=False)


Shape = Union[Plane, Box, Sphere, Cylinder, Torus, Blob]


@dataclass(frozen=True, kw_only=True)
class AssetFile:
    """A file named inside a mesh file (an OBJ's MTL, a texture map, a glTF buffer or image),
    checked to lie inside the mesh's folder; hashed with the spec."""

    path: Path = part(unit="absolute path")
    path_as_written: str = part(unit="the name as written in the asset file (relative to the "
                                     "mesh's folder)")


@dataclass(frozen=True, kw_only=True)
class LibraryRef:
    """A model of an asset library folder (scenegen.assets.libraries): the mesh's path is the
    layout's pattern filled with the id, inside the root."""

    layout: str = param(unit="library layout", choices=LIBRARY_LAYOUTS, key="library")
    root: str = part(unit="the library's folder as written (relative to the spec file)")
    id: str = part(unit="model id ('<synset>/<model_id>' for ShapeNet, a name for GSO and Objaverse)")


@dataclass(frozen=True, kw_only=True)
class Mesh:
    path: Path = part(unit="absolute path of a .ply/.obj/.glb/.gltf/.stl file (trimesh)")
    path_as_written: str = part(unit="the path as in the spec (relative to the spec file)")
    files: tuple[AssetFile, ...] = part((), unit="files the mesh file names (MTL, textures, "
                                        "buffers)", omit_default=True)
    own_materials: bool = part(False, unit="flag: the file's own materials are rendered (the "
                                           "object has no `material:`)", omit_default=True)
    up_axis: str = param("z", unit="axis", choices=MESH_UP_AXES, omit_default=True,
                         derived="'y' for .gltf/.glb (the glTF 2.0 spec), else 'z'")  # the file's
    # up axis; a Y-up file is turned into our Z-up object frame (scenegen.geometry.conventions)
    scale: float = param(1.0, unit="metres per file unit", lo=0.0, lo_open=True, omit_default=True)
    # uniform, applied to the file's vertices before the object's transform (ShapeNet's unit
    # diagonal -> the real diagonal in metres)
    library: LibraryRef | None = part(None, unit="the asset library model the file is (None: a "
                                      "path)", omit_default=True)
    kind: str = field(default="mesh", init=False)


_MARGIN = "one square"


@dataclass(frozen=True, kw_only=True)
class CheckerboardTarget:
    """A chessboard of (inner_cols + 1) x (inner_rows + 1) squares, centred on the object origin
    in the z = 0 plane, printed side facing +z; a white margin around it."""

    inner_cols: int = param(unit="inner corners", label="", lo=2, hi=MAX_BOARD_SIDE)  # along object x
    # (cv2.findChessboardCorners patternSize[0])
    inner_rows: int = param(unit="inner corners", label="", lo=2, hi=MAX_BOARD_SIDE)  # along object y
    square_m: float = param(**_POS_M)  # side of one square
    margin_m: float = param(unit="metres", lo=0.0, derived=_MARGIN)  # white border around the
    # squares
    kind: str = field(default="checkerboard", init=False)


@dataclass(frozen=True, kw_only=True)
class CharucoTarget:
    """A ChArUco board (cv2.aruco.CharucoBoard), centred on the object origin, z = 0, facing +z."""

    squares_x: int = param(unit="squares", label="", lo=2, hi=MAX_BOARD_SIDE)  # along object x
    squares_y: int = param(unit="squares", label="", lo=2, hi=MAX_BOARD_SIDE)  # along object y
    square_m: float = param(**_POS_M)  # side of one square
    marker_m: float = param(**_POS_M)  # side of one ArUco marker (< square_m)
    dictionary: str = param(unit="ArUco dictionary", choices=tuple(ARUCO_DICTIONARIES))
    # cv2.aruco predefined dictionary name, e.g. 'DICT_5X5_100'
    margin_m: float = param(unit="metres", lo=0.0, derived=_MARGIN)  # white border
    legacy_pattern: bool = param(False, unit="flag", omit_default=True)  # OpenCV's layout before
    # 4.6 (setLegacyPattern): with an even squares_y the top-left square is white
    kind: str = field(default="charuco", init=False)


@dataclass(frozen=True, kw_only=True)
class ArucoGridTarget:
    """An ArUco grid board (cv2.aruco.GridBoard), centred on the object origin, z = 0, facing +z."""

    markers_x: int = param(unit="markers", label="", lo=1, hi=MAX_BOARD_SIDE)  # along object x
    markers_y: int = param(unit="markers", label="", lo=1, hi=MAX_BOARD_SIDE)  # along object y
    marker_m: float = param(**_POS_M)  # side of one marker
    separation_m: float = param(**_POS_M)  # gap between neighbouring markers
    dictionary: str = param(unit="ArUco dictionary", choices=tuple(ARUCO_DICTIONARIES))
    margin_m: float = param(unit="metres", lo=0.0, derived="one separation")  # white border
    first_id: int = param(0, unit="marker id", label="", lo=0)  # ids run row by row
    kind: str = field(default="aruco_grid", init=False)


Target = Union[CheckerboardTarget, CharucoTarget, ArucoGridTarget]


@dataclass(frozen=True, kw_only=True, eq=False)
class Transform:
    """Object placement: ``x_world = world_from_object.R @ (scale * x_object) + world_from_object.t``."""

    world_from_object: Rigid3 = part(default_factory=Rigid3.identity, unit="rotation + "
                                     "translation (metres)")
    scale: tuple[float, float, float] = param((1.0, 1.0, 1.0), unit="unitless", lo=0.0,
                                              lo_open=True)  # per axis

    @property
    def matrix(self) -> np.ndarray:
        """(4, 4) object-to-world matrix including the scale."""
        T = self.world_from_object.matrix
        T[:3, :3] = T[:3, :3] * np.asarray(self.scale)[None, :]
        return T


@dataclass(frozen=True, kw_only=True, eq=False)
class SceneObject:
    name: str  # unique among objects
    geometry: Union[Shape, Mesh, Target]  # exactly one of shape / mesh / target
    transform: Transform  # object-to-world placement
    material: Material  # resolved: the named material from `materials:` or an inline one
    object_id: int  # 1-based position in `objects:` (0 is the background in id images)
    instance_id: int = param(unit="instance id", label="", lo=1, hi=ID_MAX, derived="the object "
                             "id")  # may be shared between objects
    motion: Any = part(None, unit="scenegen.geometry.optics.Motion in the world, about the "
                                  "object origin; None = static")
    animation: Any = part(None, unit="scenegen.spec.model.timeline.Animation over the sequence "
                                     "(trajectory, parent, joint, visible_s); None = static. With "
                                     "one, `transform` is the object's pose at frame 0",
                          omit_default=True)
    annotation: Any = part(None, unit="scenegen.spec.model.annotation.Annotation: the model it is an "
                                      "instance of, symmetries, keypoints, skeleton; None = not annotated",
                           omit_default=True)
    where: Where | None = where_field()
