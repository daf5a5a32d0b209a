"""The scene spec as frozen dataclasses: what :func:`scenegen.spec.load_spec` returns.

Conventions (see :mod:`scenegen.geometry.conventions`): the world is right-handed and Z-up, in metres;
camera axes are OpenCV's (+x right, +y down, +z forward); pixel (0, 0) is the CENTRE of the
top-left pixel. Angles are degrees only in fields named ``*_deg`` (as written by the user);
resolved rotations are matrices inside :class:`~scenegen.geometry.pose.Rigid3`. Quaternions are (w, x, y, z).

Every record that came from the YAML keeps ``where`` (file, line, field path) so that later
stages can report a problem at its source with :meth:`scenegen.errors.SpecError.at`.
``where`` takes no part in equality.

Paths to files (meshes, images) are absolute, resolved relative to the spec file's directory;
``*_as_written`` keeps the user's spelling for provenance and hashing.
"""
from __future__ import annotations

import math

from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping, Union

import numpy as np

from scenegen.errors import Where
from scenegen.geometry.pose import Rigid3

_WHERE = dict(default=None, compare=False, repr=False)

#: Allowed values of the enumerations, in the order the docs list them.
RENDER_VARIANTS = ("auto", "llvm_ad_rgb", "cuda_ad_rgb", "scalar_rgb")
SAMPLERS = ("ldsampler", "multijitter", "stratified", "orthogonal", "independent")


def effective_spp(sampler: str, spp: int) -> int:
    """Samples per pixel Mitsuba 3.9's ``sampler`` actually takes when asked for ``spp`` (its
    plugins round the count up; tested against ``mi.load_dict(...).sample_count()`` in
    tests/test_render.py): ``ldsampler`` to a power of 4 (at least 4), ``orthogonal`` to the
    square of a prime, ``stratified`` to a square, ``multijitter`` to ``m * ceil(spp / m)`` with
    ``m = floor(sqrt(spp))``, ``independent`` not at all."""
    n = int(spp)
    if sampler == "ldsampler":
        k = 4
        while k < n:
            k *= 4
        return k
    if sampler == "orthogonal":
        p = 2
        while p * p < n or any(p % d == 0 for d in range(2, math.isqrt(p) + 1)):
            p += 1
        return p * p
    if sampler == "stratified":
        r = math.isqrt(n)
        return r * r if r * r == n else (r + 1) ** 2
    if sampler == "multijitter":
        m = math.isqrt(n)
        return m * -(-n // m)
    return n
BIT_DEPTHS = (8, 16)
TEXTURE_KINDS = ("image", "checkerboard", "noise", "speckle", "natural")
PROCEDURAL_TEXTURE_KINDS = TEXTURE_KINDS[1:]
MATERIAL_TYPES = ("diffuse", "plastic", "conductor")
SHAPE_KINDS = ("plane", "box", "sphere", "cylinder", "torus", "blob")
MESH_SUFFIXES = (".ply", ".obj", ".glb", ".gltf", ".stl")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".exr", ".hdr", ".tif", ".tiff", ".bmp")
TARGET_KINDS = ("checkerboard", "charuco", "aruco_grid")
LIGHT_TYPES = ("area", "point", "spot", "constant", "envmap")
CAMERA_MODELS = ("pinhole", "opencv", "fisheye")
#: Allowed lengths of ``dist`` per camera model (OpenCV's coefficient order).
DIST_LENGTHS = {"pinhole": (0,), "opencv": (4, 5, 8, 12), "fisheye": (4,)}
RIG_TYPES = ("stereo", "multi")
#: Conductor names Mitsuba 3 knows (its ``conductor``/``roughconductor`` ``material`` values).
CONDUCTOR_NAMES = (
    "none", "a-C", "Ag", "Al", "AlAs", "AlAs_palik", "AlSb", "AlSb_palik", "Au", "Be", "Be_palik",
    "Cr", "CsI", "CsI_palik", "Cu", "Cu_palik", "Cu2O", "Cu2O_palik", "CuO", "CuO_palik", "d-C",
    "d-C_palik", "Hg", "Hg_palik", "HgTe", "HgTe_palik", "Ir", "Ir_palik", "K", "K_palik", "Li",
    "Li_palik", "MgO", "MgO_palik", "Mo", "Mo_palik", "Na_palik", "Nb", "Nb_palik", "Ni_palik",
    "Rh", "Rh_palik", "Se", "Se_palik", "SiC", "SiC_palik", "SnTe", "SnTe_palik", "Ta",
    "Ta_palik", "Te", "Te_palik", "ThF4", "ThF4_palik", "TiC", "TiC_palik", "TiN", "TiN_palik",
    "TiO2", "TiO2_palik", "VC", "VC_palik", "V_palik", "VN", "VN_palik", "W", "W_palik",
)
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


def frozen_mapping(d: Mapping | None = None) -> Mapping:
    """A read-only view of a dict (insertion order kept)."""
    return MappingProxyType(dict(d or {}))


# ---------------------------------------------------------------------------------------------
# render settings
@dataclass(frozen=True, kw_only=True)
class RenderSettings:
    spp: int = 64  # samples per pixel asked for; Mitsuba may round it up (effective_spp)
    max_depth: int = 6  # longest light path in segments (Mitsuba max_depth; -1 = unbounded)
    seed: int = 0  # sampler seed (image noise); independent of the scene seed
    variant: str = "auto"  # one of RENDER_VARIANTS; 'auto' lets the renderer pick
    bit_depth: int = 8  # PNG bits per channel of the rendered images: 8 or 16
    sampler: str = "ldsampler"  # one of SAMPLERS (Mitsuba sampler plugin name)
    motion_subframes: int = 8  # sub-frames averaged when objects move during the exposure
    where: Where | None = field(**_WHERE)


# ---------------------------------------------------------------------------------------------
# textures and materials
@dataclass(frozen=True, kw_only=True)
class Texture:
    kind: str  # one of TEXTURE_KINDS
    path: Path | None = None  # image file (absolute) for kind 'image'; None for procedural
    path_as_written: str | None = None  # the path as in the spec (relative to the spec file)
    params: Mapping[str, Any] = field(default_factory=frozen_mapping)  # procedural parameters,
    # passed unchanged to scenegen.assets.textures.make_texture(kind, params, seed); empty for 'image'
    seed: int = 0  # procedural seed (explicit, or derived from the scene seed and field path)
    where: Where | None = field(**_WHERE)


@dataclass(frozen=True, kw_only=True)
class DiffuseMaterial:
    name: str | None = None  # key under `materials:`; None for an inline material
    color: tuple[float, float, float] | None = (0.5, 0.5, 0.5)  # linear RGB reflectance in
    # [0, 1]; None when `texture` is given
    texture: Texture | None = None  # reflectance texture (replaces color)
    where: Where | None = field(**_WHERE)
    type: str = field(default="diffuse", init=False)


@dataclass(frozen=True, kw_only=True)
class PlasticMaterial:
    name: str | None = None  # key under `materials:`; None for an inline material
    color: tuple[float, float, float] | None = (0.5, 0.5, 0.5)  # linear RGB diffuse reflectance
    # in [0, 1]; None when `texture` is given
    texture: Texture | None = None  # diffuse reflectance texture (replaces color)
    roughness: float = 0.1  # GGX alpha (unitless, >= 0); 0 = smooth plastic
    ior: float = 1.49  # interior index of refraction (unitless, > 1); exterior is air (1.000277)
    where: Where | None = field(**_WHERE)
    type: str = field(default="plastic", init=False)


@dataclass(frozen=True, kw_only=True)
class ConductorMaterial:
    name: str | None = None  # key under `materials:`; None for an inline material
    material: str = "Al"  # Mitsuba conductor name (CONDUCTOR_NAMES), e.g. 'Al', 'Cu', 'Au'
    roughness: float = 0.1  # GGX alpha (unitless, >= 0); 0 = smooth mirror-like conductor
    where: Where | None = field(**_WHERE)
    type: str = field(default="conductor", init=False)


Material = Union[DiffuseMaterial, PlasticMaterial, ConductorMaterial]


# ---------------------------------------------------------------------------------------------
# geometry: procedural shapes (all centred on the object origin), meshes, calibration targets
@dataclass(frozen=True, kw_only=True)
class Plane:
    size: tuple[float, float] = (1.0, 1.0)  # metres along object x and y; lies in z = 0, normal +z
    kind: str = field(default="plane", init=False)


@dataclass(frozen=True, kw_only=True)
class Box:
    size: tuple[float, float, float] = (1.0, 1.0, 1.0)  # full edge lengths in metres (x, y, z)
    kind: str = field(default="box", init=False)


@dataclass(frozen=True, kw_only=True)
class Sphere:
    radius: float = 0.5  # metres
    kind: str = field(default="sphere", init=False)


@dataclass(frozen=True, kw_only=True)
class Cylinder:
    radius: float = 0.5  # metres
    height: float = 1.0  # metres along object z, from -height/2 to +height/2 (closed by caps)
    kind: str = field(default="cylinder", init=False)


@dataclass(frozen=True, kw_only=True)
class Torus:
    major_radius: float = 0.5  # metres, centre of the tube to the z axis; in the xy plane
    minor_radius: float = 0.15  # metres, tube radius (< major_radius)
    kind: str = field(default="torus", init=False)


@dataclass(frozen=True, kw_only=True)
class Blob:
    radius: float = 0.5  # metres, radius of the undisplaced sphere
    amplitude: float = 0.15  # radial displacement as a fraction of radius, in [0, 1)
    frequency: float = 2.0  # noise cycles per unit length on the unit sphere (> 0)
    subdivisions: int = 5  # icosphere subdivision level, 1..7 (20 * 4**n triangles)
    seed: int = 0  # noise seed (explicit, or derived from the scene seed and field path)
    kind: str = field(default="blob", init=False)


Shape = Union[Plane, Box, Sphere, Cylinder, Torus, Blob]


@dataclass(frozen=True, kw_only=True)
class Mesh:
    path: Path  # absolute path of a .ply/.obj/.glb/.gltf/.stl file (loaded with trimesh)
    path_as_written: str  # the path as in the spec (relative to the spec file)
    kind: str = field(default="mesh", init=False)


@dataclass(frozen=True, kw_only=True)
class CheckerboardTarget:
    """A chessboard of (inner_cols + 1) x (inner_rows + 1) squares, centred on the object origin
    in the z = 0 plane, printed side facing +z; a white margin around it."""

    inner_cols: int  # inner corners along object x (cv2.findChessboardCorners patternSize[0])
    inner_rows: int  # inner corners along object y (patternSize[1])
    square_m: float  # side of one square, metres
    margin_m: float  # white border around the squares, metres (default: one square)
    kind: str = field(default="checkerboard", init=False)


@dataclass(frozen=True, kw_only=True)
class CharucoTarget:
    """A ChArUco board (cv2.aruco.CharucoBoard), centred on the object origin, z = 0, facing +z."""

    squares_x: int  # chessboard squares along object x
    squares_y: int  # chessboard squares along object y
    square_m: float  # side of one square, metres
    marker_m: float  # side of one ArUco marker, metres (< square_m)
    dictionary: str  # cv2.aruco predefined dictionary name, e.g. 'DICT_5X5_100'
    margin_m: float  # white border around the board, metres (default: one square)
    kind: str = field(default="charuco", init=False)


@dataclass(frozen=True, kw_only=True)
class ArucoGridTarget:
    """An ArUco grid board (cv2.aruco.GridBoard), centred on the object origin, z = 0, facing +z."""

    markers_x: int  # markers along object x
    markers_y: int  # markers along object y
    marker_m: float  # side of one marker, metres
    separation_m: float  # gap between neighbouring markers, metres
    dictionary: str  # cv2.aruco predefined dictionary name
    margin_m: float  # white border around the grid, metres (default: one separation)
    first_id: int = 0  # id of the first marker (ids run row by row)
    kind: str = field(default="aruco_grid", init=False)


Target = Union[CheckerboardTarget, CharucoTarget, ArucoGridTarget]


@dataclass(frozen=True, kw_only=True, eq=False)
class Transform:
    """Object placement: ``x_world = world_from_object.R @ (scale * x_object) + world_from_object.t``."""

    world_from_object: Rigid3 = field(default_factory=Rigid3.identity)  # rotation + translation (m)
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)  # per-axis scale (unitless, > 0)

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
    instance_id: int  # as given, default = object_id (>= 1; may be shared between objects)
    motion: Any = None  # scenegen.geometry.optics.Motion in the world, about the object origin; None = static
    where: Where | None = field(**_WHERE)


# ---------------------------------------------------------------------------------------------
# lights (radiance in W/(m^2 sr), intensity in W/sr, linear RGB)
@dataclass(frozen=True, kw_only=True, eq=False)
class AreaLight:
    name: str  # unique among lights (default 'light<i>')
    size: tuple[float, float]  # rectangle side lengths along the light's x and y, metres
    world_from_light: Rigid3  # the rectangle lies in the light's z = 0 plane and emits toward +z
    radiance: tuple[float, float, float]  # emitted radiance, linear RGB, W/(m^2 sr)
    where: Where | None = field(**_WHERE)
    type: str = field(default="area", init=False)


@dataclass(frozen=True, kw_only=True)
class PointLight:
    name: str
    position: tuple[float, float, float]  # metres, world
    intensity: tuple[float, float, float]  # radiant intensity, linear RGB, W/sr
    where: Where | None = field(**_WHERE)
    type: str = field(default="point", init=False)


@dataclass(frozen=True, kw_only=True, eq=False)
class SpotLight:
    name: str
    position: tuple[float, float, float]  # metres, world
    target: tuple[float, float, float]  # point the spot's axis passes through, metres, world
    world_from_light: Rigid3  # light frame: origin at position, +z toward target
    intensity: tuple[float, float, float]  # on-axis radiant intensity, linear RGB, W/sr
    cutoff_deg: float  # half-angle of the cone, degrees, in (0, 90]
    beam_width_deg: float  # half-angle of full intensity, degrees (default 0.75 * cutoff)
    where: Where | None = field(**_WHERE)
    type: str = field(default="spot", init=False)


@dataclass(frozen=True, kw_only=True)
class ConstantLight:
    name: str
    radiance: tuple[float, float, float]  # uniform environment radiance, linear RGB, W/(m^2 sr)
    where: Where | None = field(**_WHERE)
    type: str = field(default="constant", init=False)


@dataclass(frozen=True, kw_only=True)
class EnvmapLight:
    """Equirectangular image; its top row is world +z (up); turned by rotation_z_deg about +z."""

    name: str
    path: Path  # absolute path of the image (EXR/HDR preferred: linear radiance)
    path_as_written: str  # as in the spec
    scale: float = 1.0  # radiance multiplier (unitless, >= 0)
    rotation_z_deg: float = 0.0  # turn about world +z, degrees
    where: Where | None = field(**_WHERE)
    type: str = field(default="envmap", init=False)


Light = Union[AreaLight, PointLight, SpotLight, ConstantLight, EnvmapLight]


# ---------------------------------------------------------------------------------------------
# cameras and rigs
@dataclass(frozen=True, kw_only=True)
class CameraSpec:
    """Intrinsics (OpenCV pixel convention: pixel (0, 0) is the top-left pixel's centre).

    ``dist`` is in OpenCV's order: opencv k1, k2, p1, p2[, k3[, k4, k5, k6[, s1, s2, s3, s4]]];
    fisheye (Kannala-Brandt, cv2.fisheye) k1, k2, k3, k4; pinhole ().
    """

    name: str  # key under `cameras:`
    model: str  # one of CAMERA_MODELS
    width: int  # pixels
    height: int  # pixels
    fx: float  # focal length along u, pixels
    fy: float  # focal length along v, pixels
    cx: float  # principal point u, pixels
    cy: float  # principal point v, pixels
    skew: float = 0.0  # K[0, 1], pixels
    dist: tuple[float, ...] = ()  # distortion coefficients (unitless), see above
    fov_deg: float | None = None  # horizontal FoV of the undistorted pinhole as written (fx, fy
    # derived from it: fx = fy = (W/2) / tan(fov/2)), degrees
    optics: Any = None  # scenegen.geometry.optics.Optics: thin lens, shutter (motion blur, rolling
    # shutter), chromatic aberration; None = a pinhole with an instantaneous global shutter
    imaging: Any = None  # scenegen.imaging.ImagingParams: the photometric chain (exposure,
    # vignetting, EMVA 1288 sensor, Bayer, response; docs/image_formation.md); None = the clean
    # sRGB encoding of the linear render
    where: Where | None = field(**_WHERE)

    @property
    def size(self) -> tuple[int, int]:
        """(W, H) in pixels."""
        return (self.width, self.height)

    @property
    def K(self) -> np.ndarray:
        """(3, 3) intrinsic matrix."""
        return np.array([[self.fx, self.skew, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def to_camera(self):
        """The :class:`scenegen.geometry.camera.Camera` for these intrinsics (imported on use)."""
        from scenegen.geometry.camera import Camera

        return Camera(model=self.model, width=self.width, height=self.height, fx=self.fx,
                      fy=self.fy, cx=self.cx, cy=self.cy, skew=self.skew, dist=self.dist)


@dataclass(frozen=True, kw_only=True, eq=False)
class RigMember:
    name: str  # 'left'/'right' for stereo; for multi the given name (default: camera name)
    camera: str  # a key of `cameras:`
    rig_from_cam: Rigid3  # camera pose in the rig frame (metres)


@dataclass(frozen=True, kw_only=True, eq=False)
class Rig:
    """Camera rig. The rig frame has OpenCV camera axes. Stereo: its origin is the left camera
    centre; the right camera centre is at (+baseline_m, 0, 0); with vergence each camera is
    turned by vergence_deg / 2 about its own y axis toward the other (toe-in)."""

    name: str  # key under `rigs:`
    type: str  # 'stereo' | 'multi'
    members: tuple[RigMember, ...]  # stereo: (left, right)
    baseline_m: float | None = None  # stereo only: distance between the camera centres, metres
    vergence_deg: float | None = None  # stereo only: total toe-in angle, degrees
    where: Where | None = field(**_WHERE)


# ---------------------------------------------------------------------------------------------
# view sets (placements of a camera or of a rig's frame)
@dataclass(frozen=True, kw_only=True)
class Orbit:
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)  # point looked at, metres
    radius_m: float  # distance from center to the eye, metres
    elevations_deg: tuple[float, ...] = (30.0,)  # above the xy plane through center, degrees
    count: int  # views per elevation, evenly spaced in azimuth
    start_azimuth_deg: float = 0.0  # azimuth of the first view, from +x toward +y, degrees
    kind: str = field(default="orbit", init=False)


@dataclass(frozen=True, kw_only=True)
class LookAt:
    eye: tuple[float, float, float]  # metres, world
    target: tuple[float, float, float]  # metres, world
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)  # world direction shown up in the image


@dataclass(frozen=True, kw_only=True)
class LookAtList:
    entries: tuple[LookAt, ...]
    kind: str = field(default="look_at", init=False)


@dataclass(frozen=True, kw_only=True, eq=False)
class PoseList:
    world_from_cam: tuple[Rigid3, ...]  # camera (or, for a rig view set, rig) to world
    kind: str = field(default="poses", init=False)


@dataclass(frozen=True, kw_only=True)
class RandomPoses:
    count: int  # number of views
    seed: int  # explicit, or derived from the scene seed and field path
    eye_min: tuple[float, float, float]  # eye box corner, metres
    eye_max: tuple[float, float, float]
    target_min: tuple[float, float, float]  # target box (min == max for a fixed target), metres
    target_max: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    min_distance_m: float = 0.0  # eye-target distances below this are redrawn, metres
    kind: str = field(default="random", init=False)


@dataclass(frozen=True, kw_only=True)
class LinePath:
    start: tuple[float, float, float]  # first eye (YAML `from`), metres
    end: tuple[float, float, float]  # last eye (YAML `to`), metres
    count: int  # eyes evenly spaced from start to end, both included
    target: tuple[float, float, float]  # metres
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    kind: str = field(default="line", init=False)


@dataclass(frozen=True, kw_only=True)
class CirclePath:
    center: tuple[float, float, float]  # circle centre, metres
    radius_m: float  # metres
    height_m: float  # eyes at center + (r cos a, r sin a, height_m), metres
    count: int  # eyes evenly spaced over 360 degrees (the start is not repeated)
    start_azimuth_deg: float  # degrees, from +x toward +y
    target: tuple[float, float, float]  # metres (default: center)
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    kind: str = field(default="circle", init=False)


Placement = Union[Orbit, LookAtList, PoseList, RandomPoses, LinePath, CirclePath]


@dataclass(frozen=True, kw_only=True)
class ViewSet:
    name: str | None  # optional; prefix of the view names (default: camera or rig name)
    camera: str | None  # a key of `cameras:` (exactly one of camera / rig)
    rig: str | None  # a key of `rigs:`
    placement: Placement  # where the camera (or the rig frame) goes
    motion: Any = None  # scenegen.geometry.optics.Motion of the placed camera / rig frame (body velocities)
    lights: Mapping[str, float] | None = None  # illumination of this view set: every spec light
    # (spec order) -> factor (>= 0) on its spec power, 0 = off; None = every light at its power
    where: Where | None = field(**_WHERE)

    @property
    def prefix(self) -> str:
        return self.name or self.camera or self.rig  # type: ignore[return-value]


@dataclass(frozen=True, kw_only=True, eq=False)
class View:
    """One image to render: a camera at a pose."""

    name: str  # unique, e.g. 'left_0003' or 'stereo_right_0012' (see resolve_views)
    camera: str  # key of `cameras:`
    cam_from_world: Rigid3  # pose, metres
    rig: str | None = None  # rig name, or None for a lone camera
    rig_member: str | None = None  # member name in the rig ('left', 'right', ...)
    frame_index: int = 0  # placement counter over all view sets; a rig's members share it
    view_set: int = 0  # index of the view set in `views:`
    motion: Any = None  # scenegen.geometry.optics.Motion of this camera, in its own frame; None = static
    light_scales: tuple[float, ...] | None = None  # factor on each spec light's power (spec
    # order; 0 = off) from the view set's `lights:`; None = every light at its spec power


# ---------------------------------------------------------------------------------------------
# cross-view truth (docs/crossview.md)
CROSSVIEW_PAIR_MODES = ("consecutive", "all", "none")


@dataclass(frozen=True, kw_only=True)
class MatchSetSpec:
    """Putative match sets sampled from visible truth correspondences (per selected pair)."""

    count: int = 1000  # matches per pair (fewer when fewer pixels are visible)
    sigma_px: float = 0.5  # Gaussian noise of inliers, px, per coordinate of both points
    outlier_fraction: float = 0.2  # share of outliers, in [0, 1)
    near_miss_fraction: float = 0.5  # share of the outliers that are near misses, in [0, 1]
    near_miss_px: tuple[float, float] = (4.0, 16.0)  # near-miss distance range from the truth, px
    seed: int = 0  # explicit, or derived from the scene seed and field path
    where: Where | None = field(**_WHERE)


@dataclass(frozen=True, kw_only=True)
class CrossviewSpec:
    """What cross-view truth to write (the optional top-level ``crossview:`` section)."""

    pairs: Union[str, tuple[tuple[str, str], ...]] = "consecutive"  # CROSSVIEW_PAIR_MODES or
    # explicit (view_a, view_b) names; dense correspondences both ways + two-view geometry
    flow: bool = True  # Middlebury .flo flow between consecutive frames of each camera stream
    stereo: bool = True  # rectified renders, disparity and maps for every stereo-rig frame
    matches: MatchSetSpec | None = None  # synthetic labelled match sets per pair (None = off)
    sift: bool = False  # OpenCV SIFT matches per pair, labelled against the truth
    sift_ratio: float = 0.8  # Lowe's ratio test threshold, in (0, 1]
    sift_inlier_px: float = 2.0  # a SIFT match is an inlier within this distance of the truth, px
    targets: bool = True  # per-view calibration-board corner truth (when the scene has boards)
    where: Where | None = field(**_WHERE)


# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True, kw_only=True, eq=False)
class SceneSpec:
    name: str  # scene name (default: the spec file's stem)
    description: str = ""  # free text
    seed: int = 0  # scene seed: default seeds of procedural textures, blobs and random views
    render: RenderSettings = field(default_factory=RenderSettings)
    materials: Mapping[str, Material] = field(default_factory=frozen_mapping)  # by name
    objects: tuple[SceneObject, ...] = ()
    lights: tuple[Light, ...] = ()
    cameras: Mapping[str, CameraSpec] = field(default_factory=frozen_mapping)  # by name
    rigs: Mapping[str, Rig] = field(default_factory=frozen_mapping)  # by name
    view_sets: tuple[ViewSet, ...] = ()  # the `views:` list
    file: str | None = None  # the spec file as named by the user ('<string>' for text)
    base_dir: Path = field(default_factory=Path.cwd)  # directory relative paths resolve against
    warnings: tuple[str, ...] = ()  # non-fatal remarks, each 'file:line: field: message'
    crossview: CrossviewSpec | None = None  # cross-view truth to write; None = none
    variation: Any = None  # scenegen.spec.variation.VariationSpec: seeded ranges for
    # `scenegen render --variants N`; None = no variation declared
    variant: Mapping[str, Any] | None = None  # a derived variant's index, seed and drawn values
    # (scenegen.spec.variants.derive_variant); None for the spec as written
