"""Every convention of the project, stated once, and the one conversion to each foreign one.

Internal conventions (used everywhere in scenegen and recon_eval):

* Camera axes: OpenCV. +x right, +y down, +z forward (the optical axis). A pose is
  ``cam_from_world`` (``x_cam = R x_world + t``), see :mod:`scenegen.geometry.pose`.
* Units: metres; radians inside the code, degrees only at the user's edges (spec fields and result
  fields named ``*_deg``).
* Pixels: OpenCV. The CENTRE of the top-left pixel is (u, v) = (0, 0); u grows to the right along
  columns, v down along rows; the image spans [-0.5, W - 0.5] x [-0.5, H - 0.5].
* Depth is z along the optical axis (``depth_z``); range is the Euclidean distance from the optical
  centre (``range``). ``range = depth_z * |(x, y, 1)|`` for the z = 1 ray (x, y, 1).
* Quaternions are (w, x, y, z), scalar first (COLMAP's order).
* Texture UVs: u along texture columns, v along rows with v = 0 at the top row (image row 0).
* World: right-handed, +z up (``WORLD_UP`` of the spec's look-ats). Gravity is
  ``GRAVITY_WORLD_MPS2 = (0, 0, -9.80665)`` m/s^2 (standard gravity, pointing down), and an
  accelerometer measures the specific force ``f_body = R_world_from_body^T (a_world - g_world)``:
  at rest with +z up it reads (0, 0, +9.80665) (:mod:`scenegen.geometry.imu`).
* A LiDAR's frame: +x forward, +y left, +z up (a Velodyne's, KITTI's velodyne frame); a beam's
  azimuth counter-clockwise from +x seen from above, its elevation up from the xy plane
  (:mod:`scenegen.geometry.lidar`).

Foreign conventions, one function (or constant) each:

* COLMAP pixels: the top-left pixel's centre is (0.5, 0.5): ``colmap = opencv + 0.5``.
* COCO boxes ``[x, y, w, h]`` are in pixel-edge coordinates (the top-left pixel covers [0, 1]^2):
  the box of the pixels whose centres span ``[u_min, u_max] x [v_min, v_max]`` is
  ``[u_min, v_min, u_max - u_min + 1, v_max - v_min + 1]`` (``coco_box_of_pixels``); an extent of
  OpenCV positions is ``[u_min + 0.5, v_min + 0.5, u_max - u_min, v_max - v_min]``
  (``coco_box_of_extent``). COCO keypoints and run-length masks are in the same frame:
  ``coco = opencv + 0.5`` (``coco_points``); a mask's RLE runs down the columns (Fortran order).
* 3D box corners: corner k of a box with centre c and size s is ``c + BOX_CORNER_SIGNS[k] * s / 2``,
  the signs (-1, +1) in itertools.product order (x slowest, z fastest).
* Mitsuba film: sample position s in [0, 1]^2 over the image, pixel i covers [i, i + 1] in film
  pixel units, so ``u = s_x * W - 0.5``. Mitsuba camera axes: +x LEFT, +y UP, +z forward (a 180
  degree rotation about z from OpenCV). Its ``to_world`` is camera-to-world.
* OpenGL / NeRF (instant-ngp, nerfstudio ``transforms.json``): camera-to-world 4x4 with camera axes
  +x right, +y up, +z backward (the camera looks down -z).
* Blender: a camera object's ``matrix_world`` uses the OpenGL camera axes; Blender's world is the
  same right-handed Z-up world as ours, so no world change is needed.
* COLMAP poses: ``cam_from_world`` as a wxyz quaternion and a translation (images.txt).
* Mesh files: glTF 2.0 is Y-up by its specification (+Y up, +Z the asset's front, right-handed);
  a Y-up file's vertices enter our Z-up world through ``Z_UP_FROM_Y_UP`` (+90 degrees about x:
  (x, y, z) -> (x, -z, y), what Blender's glTF importer does). Other mesh formats carry no axis
  convention and are read as Z-up (``mesh_up_axis``).
"""
from __future__ import annotations

import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_quat_wxyz, quat_wxyz_from_matrix

# --- camera axes -----------------------------------------------------------------------------
#: Gravity in the Z-up world frame, m/s^2 (standard gravity, 9.80665, CGPM 1901).
GRAVITY_WORLD_MPS2 = np.array([0.0, 0.0, -9.80665])
#: x_mitsuba_cam = MITSUBA_FROM_OPENCV_CAM @ x_opencv_cam (x left, y up, z forward).
MITSUBA_FROM_OPENCV_CAM = np.diag([-1.0, -1.0, 1.0])
#: x_opengl_cam = OPENGL_FROM_OPENCV_CAM @ x_opencv_cam (x right, y up, z backward).
OPENGL_FROM_OPENCV_CAM = np.diag([1.0, -1.0, -1.0])
#: x_diligent_cam = DILIGENT_FROM_OPENCV_CAM @ x_opencv_cam: the photometric stereo benchmark
#: DiLiGenT states normals (Normal_gt.mat) and light directions (light_directions.txt, unit
#: vectors toward the light) with x right, y up, z toward the camera: OpenGL's axes.
DILIGENT_FROM_OPENCV_CAM = OPENGL_FROM_OPENCV_CAM


def _camera_to_world(cam_from_world: Rigid3, foreign_from_opencv: np.ndarray) -> np.ndarray:
    """4x4 camera-to-world of a camera frame with other axes (x_foreign = A x_opencv)."""
    world_from_cam = cam_from_world.inverse()
    T = np.eye(4)
    T[:3, :3] = world_from_cam.R @ foreign_from_opencv.T
    T[:3, 3] = world_from_cam.t
    return T


def _cam_from_world(camera_to_world, foreign_from_opencv: np.ndarray) -> Rigid3:
    T = np.asarray(camera_to_world, dtype=np.float64)
    return Rigid3(T[:3, :3] @ foreign_from_opencv, T[:3, 3]).inverse()


def mitsuba_to_world(cam_from_world: Rigid3) -> np.ndarray:
    """Mitsuba sensor ``to_world`` (4x4, Mitsuba camera -> world) for an OpenCV ``cam_from_world``."""
    return _camera_to_world(cam_from_world, MITSUBA_FROM_OPENCV_CAM)


def cam_from_world_from_mitsuba(to_world) -> Rigid3:
    """Inverse of :func:`mitsuba_to_world`."""
    return _cam_from_world(to_world, MITSUBA_FROM_OPENCV_CAM)


def opengl_cam_to_world(cam_from_world: Rigid3) -> np.ndarray:
    """OpenGL/NeRF camera-to-world 4x4 (``transform_matrix`` of transforms.json); also Blender's
    camera ``matrix_world``."""
    return _camera_to_world(cam_from_world, OPENGL_FROM_OPENCV_CAM)


def cam_from_world_from_opengl(cam_to_world) -> Rigid3:
    """Inverse of :func:`opengl_cam_to_world`."""
    return _cam_from_world(cam_to_world, OPENGL_FROM_OPENCV_CAM)


# Blender cameras use the OpenGL camera axes in a Z-up world identical to ours.
blender_matrix_world = opengl_cam_to_world
cam_from_world_from_blender = cam_from_world_from_opengl


# --- mesh files ------------------------------------------------------------------------------
#: x_world = Z_UP_FROM_Y_UP @ x_file for a Y-up file (glTF 2.0): +90 degrees about x, so the
#: file's +Y (up) becomes +z and its +Z (the asset's front) becomes -y.
Z_UP_FROM_Y_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
#: A mesh file's up axis -> the rotation taking its vertices into our Z-up frame.
ZUP_FROM_MESH_UP = {"z": np.eye(3), "y": Z_UP_FROM_Y_UP}
#: File suffixes whose format fixes the up axis (glTF 2.0 spec, "Coordinate System and Units").
Y_UP_SUFFIXES = (".gltf", ".glb")


def mesh_up_axis(suffix: str) -> str:
    """The up axis a mesh file of this suffix is read with by default: 'y' for glTF (its
    specification says so), 'z' for PLY, OBJ, STL (formats without an axis convention)."""
    return "y" if suffix.lower() in Y_UP_SUFFIXES else "z"


def zup_from_mesh_file(vertices, up_axis: str) -> np.ndarray:
    """(N, 3) float64 vertices of a mesh file with up axis ``up_axis`` ('y' or 'z') in our Z-up
    object frame (a rotation: the winding is kept)."""
    R = ZUP_FROM_MESH_UP[up_axis]
    v = np.asarray(vertices, dtype=np.float64)
    return v if up_axis == "z" else v @ R.T


# --- COLMAP poses ------------------------------------------------------------------------------
def colmap_pose(cam_from_world: Rigid3) -> tuple[np.ndarray, np.ndarray]:
    """(qvec_wxyz, tvec) as written in COLMAP's images.txt (cam_from_world)."""
    return quat_wxyz_from_matrix(cam_from_world.R), cam_from_world.t.copy()


def cam_from_world_from_colmap(qvec_wxyz, tvec) -> Rigid3:
    return Rigid3(matrix_from_quat_wxyz(qvec_wxyz), tvec)


# --- pixels -----------------------------------------------------------------------------------
def colmap_from_opencv_pixels(uv):
    """COLMAP image coordinates (top-left pixel centre at 0.5) from OpenCV pixels."""
    return np.asarray(uv, dtype=np.float64) + 0.5


def opencv_from_colmap_pixels(uv):
    return np.asarray(uv, dtype=np.float64) - 0.5


def normalised_from_opencv_pixels(uv, size):
    """Coordinates over the image area, (0, 0) at the image's top-left corner and (1, 1) at its
    bottom-right corner (TAP-Vid's normalised points), from OpenCV pixels (..., 2) of an image of
    ``size`` (width, height): ``(uv + 0.5) / size``."""
    return colmap_from_opencv_pixels(uv) / np.asarray(size, dtype=np.float64)


def rescaled_opencv_pixels(uv, scale):
    """OpenCV pixels of the same image points after the image is resized by ``scale`` (sx, sy):
    the image's corners stay at its corners, so ``(uv + 0.5) * scale - 0.5``."""
    return opencv_from_colmap_pixels(colmap_from_opencv_pixels(uv) * np.asarray(scale, dtype=np.float64))


def opencv_pixel_from_film(sample, size, offset=(0, 0)):
    """OpenCV pixel from Mitsuba's film sample position in [0, 1]^2 over a crop window.

    ``size`` is the crop size (W, H) and ``offset`` its top-left pixel (both (0, 0) and the full
    image without cropping). Works on numpy and Dr.Jit values alike (only arithmetic).
    """
    return sample[0] * size[0] + offset[0] - 0.5, sample[1] * size[1] + offset[1] - 0.5


def film_from_opencv_pixel(uv, size):
    """Mitsuba film sample position in [0, 1]^2 for an OpenCV pixel (inverse of the above)."""
    return (uv[0] + 0.5) / size[0], (uv[1] + 0.5) / size[1]


def in_image(uv, width: int, height: int) -> np.ndarray:
    """(N,) bool: OpenCV pixel positions (N, 2) inside the image area [-0.5, W - 0.5] x
    [-0.5, H - 0.5] (edges included; NaN is outside)."""
    uv = np.asarray(uv, float)
    with np.errstate(invalid="ignore"):
        return (uv[:, 0] >= -0.5) & (uv[:, 0] <= width - 0.5) & (uv[:, 1] >= -0.5) & (uv[:, 1] <= height - 0.5)


def corner_pixel_centers(width: int, height: int) -> np.ndarray:
    """(4, 2) the corner pixels' centres: (0, 0), (W - 1, 0), (0, H - 1), (W - 1, H - 1)."""
    return np.array([[0.0, 0.0], [width - 1.0, 0.0], [0.0, height - 1.0], [width - 1.0, height - 1.0]])


def pixel_centers(width: int, height: int) -> np.ndarray:
    """(H, W, 2) float64 OpenCV coordinates of every pixel centre: [v, u] -> (u, v) = (u, v)."""
    u, v = np.meshgrid(np.arange(width, dtype=np.float64), np.arange(height, dtype=np.float64))
    return np.stack([u, v], axis=-1)


# --- boxes -------------------------------------------------------------------------------------
#: (8, 3) signs of a 3D box's corners: corner k = centre + BOX_CORNER_SIGNS[k] * size / 2
#: (x slowest, z fastest: (-,-,-), (-,-,+), (-,+,-), ..., (+,+,+)).
BOX_CORNER_SIGNS = np.array([[sx, sy, sz] for sx in (-1.0, 1.0) for sy in (-1.0, 1.0) for sz in (-1.0, 1.0)])


def box_corners(center, size) -> np.ndarray:
    """(8, 3) corners of the axis-aligned box with ``center`` (3,) and ``size`` (3,), in the order
    of :data:`BOX_CORNER_SIGNS`."""
    return np.asarray(center, np.float64) + BOX_CORNER_SIGNS * (np.asarray(size, np.float64) / 2.0)


def coco_box_of_pixels(box_xyxy) -> list[float]:
    """COCO ``[x, y, w, h]`` (pixel edges) of the pixels whose OpenCV centres span ``box_xyxy`` =
    ``[u_min, v_min, u_max, v_max]`` (inclusive; a single pixel u is [u, u + 1] in COCO)."""
    u0, v0, u1, v1 = (float(x) for x in box_xyxy)
    return [u0, v0, u1 - u0 + 1.0, v1 - v0 + 1.0]


def coco_box_of_extent(box_xyxy) -> list[float]:
    """COCO ``[x, y, w, h]`` (pixel edges) of an extent ``[u_min, v_min, u_max, v_max]`` of OpenCV
    positions (``coco = opencv + 0.5``, like COLMAP's)."""
    u0, v0, u1, v1 = (float(x) for x in box_xyxy)
    return [u0 + 0.5, v0 + 0.5, u1 - u0, v1 - v0]


def coco_points(uv) -> np.ndarray:
    """(N, 2) COCO keypoint positions (pixel edges) of OpenCV positions (N, 2): ``uv + 0.5``."""
    return np.asarray(uv, np.float64) + 0.5


# --- depth vs range ---------------------------------------------------------------------------
def range_from_depth_z(depth_z, rays_z1):
    """Range (distance from the optical centre) from z-depth along z = 1 rays (..., 3)."""
    return np.asarray(depth_z) * np.linalg.norm(np.asarray(rays_z1), axis=-1)


def depth_z_from_range(range_m, rays_z1):
    """z-depth from range along z = 1 rays (..., 3) (x, y, 1)."""
    return np.asarray(range_m) / np.linalg.norm(np.asarray(rays_z1), axis=-1)


def opengl_from_directx_normal_map(normals01) -> np.ndarray:
    """A tangent-space normal map stored DirectX-style (+y DOWN the image: Poly Haven's
    ``nor_dx``, Unreal) in the OpenGL / glTF convention the renderer reads (+y UP the image for an
    unmirrored texture, Mitsuba's ``normalmap``): values in [0, 1] (..., 3), the green channel
    inverted, ``g -> 1 - g`` (n_y -> -n_y)."""
    out = np.array(normals01, dtype=np.float32, copy=True)
    out[..., 1] = 1.0 - out[..., 1]
    return out


#: The ``rotation_z_deg`` of an envmap light that shows an equirectangular image as Blender's world
#: Environment Texture does (Poly Haven's HDRIs are made and previewed there). Cycles maps a
#: direction d (Blender's world: Z-up, as ours) to u = 0.5 - atan2(d_y, d_x) / 2 pi, v = 1 -
#: acos(d_z) / pi with v = 0 at the image's bottom row (``direction_to_equirectangular``), so the
#: image centre looks along +x and the azimuth is 180 deg - 360 deg * u; ours is 90 deg - 360 deg * u
#: + rotation_z_deg (:func:`envmap_direction`): the two agree at +90 deg. Both put the top row at +z.
BLENDER_ENVMAP_ROTATION_Z_DEG = 90.0


def envmap_direction(u, v, rotation_z_deg: float = 0.0) -> np.ndarray:
    """World direction (..., 3) seen at position (u, v) of an equirectangular environment map
    (u in [0, 1] left to right along the columns, v in [0, 1] top to bottom along the rows; a
    texel's centre is at ((col + 0.5) / W, (row + 0.5) / H)).

    Top row (v = 0) is world +z, bottom row -z. The image's centre (u = 0.5) looks along world
    -y, u = 0.25 along +x, u = 0.75 along -x, u = 0 and 1 along +y: the azimuth
    atan2(y, x) = 90 deg - 360 deg * u, clockwise seen from above. ``rotation_z_deg`` turns the
    map counter-clockwise about +z (the direction of u moves to azimuth + rotation_z_deg)."""
    u, v = np.broadcast_arrays(np.asarray(u, np.float64), np.asarray(v, np.float64))
    phi = np.radians(90.0 - 360.0 * u + rotation_z_deg)
    theta = np.pi * v
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)
