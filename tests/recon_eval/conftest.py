"""Fixtures shared by the recon_eval tests (seeded, small; no Mitsuba).

The analytic plane dataset, written by scenegen's own DatasetWriter. Scene: the plane z = 0 (a
6 m x 6 m square mesh of two triangles, textured as a checkerboard in the images). Views, 40 x 30 px:

* ``left_000`` and ``right_000``: a rectified stereo rig ("stereo"), identical pinhole cameras
  (fx = fy = 40, principal point at the image centre) 3 m above the plane looking straight down,
  the right one displaced by BASELINE_M along the left camera's +x axis;
* ``free_000``: an OpenCV camera with distortion, oblique, looking at the origin.

Truth per pixel centre = the camera model's own ray intersected with z = 0 (exact up to float32
storage). Cross-view truth: the correspondence file of every ordered pair of views
(``crossview/corr/<i>/<j>.exr``), states from :func:`scenegen.crossview.correspondence.correspond`
with analytic visibility (nothing occludes the plane); no crossview/index.json (the dataset has no
crossview pairs).

``occluded_plane_dataset``: the rig alone, with a thin wire (radius :data:`WIRE_RADIUS_M`, along
world y at height :data:`WIRE_HEIGHT_M`) between the cameras and the plane, placed so that it
crosses no pixel centre's ray of either camera (the depth maps show only the plane) but blocks
the ray from each camera to one column of the other's truth points (:data:`WIRE_COLUMN`): the
ray-cast states call those pixels occluded, a depth test at the nearest pixel centre visible.
"""
from __future__ import annotations

from dataclasses import dataclass

import types

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from scenegen import dataset as ds
from scenegen.crossview.correspondence import correspond
from scenegen.dataset.codecs import encode_exr
from scenegen.dataset.crossview import encode_correspondence_channels
from scenegen.dataset.layout import correspondence_path
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.dataset.codecs import encode_json, encode_png
from scenegen.dataset.codecs.exr import pack_channels
from scenegen.dataset.layout import pattern_image_path, pattern_linear_path, pattern_sequence_path, projector_truth_path
from scenegen.dataset.structured_light import PATTERNS_FORMAT, ProjectorTruth, encode_projector_truth
from scenegen.dataset.truth import LINEAR_CHANNELS
from scenegen.geometry.color import srgb_from_linear
from scenegen.geometry.conventions import pixel_centers
from scenegen.imaging.patterns import binary_to_gray, gray_code, perfect_code, sample

W, H = 40, 30
BASELINE_M = 0.5
HEIGHT_M = 3.0
PINHOLE = Camera("pinhole", W, H, 40.0, 40.0, (W - 1) / 2, (H - 1) / 2)
DISTORTED = Camera("opencv", W, H, 42.0, 41.0, 19.0, 15.0, 0.0, (-0.05, 0.01, 0.001, -0.001, 0.0))
DOWN = np.diag([1.0, -1.0, -1.0])  # cam_from_world rotation of a camera looking down -z, image x = world x
#: The wire of the occluded dataset: halfway down, seen 1/3 px from the nearest pixel centre by
#: both cameras (its half width is 0.1 px there), over left column 25 as seen from the right camera.
WIRE_HEIGHT_M = 1.5
WIRE_COLUMN = 25
# where the ray from the right camera centre to left column WIRE_COLUMN's plane point crosses the height
WIRE_X_M = BASELINE_M + (1 - WIRE_HEIGHT_M / HEIGHT_M) * ((WIRE_COLUMN - (W - 1) / 2) * HEIGHT_M / PINHOLE.fx - BASELINE_M)
WIRE_RADIUS_M = 0.1 * (HEIGHT_M - WIRE_HEIGHT_M) / PINHOLE.fx


def view_cameras() -> dict:
    left = Rigid3(DOWN, -DOWN @ np.array([0.0, 0.0, HEIGHT_M]))
    right = Rigid3(DOWN, -DOWN @ np.array([BASELINE_M, 0.0, HEIGHT_M]))
    free = look_at((1.0, -1.5, 2.5), (0.2, 0.1, 0.0)).inverse()
    return {
        "left_000": ds.ViewCamera(PINHOLE, left, "left", rig="stereo", rig_member="left", frame_index=0),
        "right_000": ds.ViewCamera(PINHOLE, right, "right", rig="stereo", rig_member="right", frame_index=0),
        "free_000": ds.ViewCamera(DISTORTED, free, "free", frame_index=0),
    }


def plane_truth(cam: Camera, pose: Rigid3) -> dict:
    uv = np.stack(np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float)), -1).reshape(-1, 2)
    d_cam = cam.unproject_unit(uv)
    world_from_cam = pose.inverse()
    c = world_from_cam.t
    d = d_cam @ world_from_cam.R.T
    s = -c[2] / d[:, 2]
    P = c + s[:, None] * d
    Pc = pose.apply(P)
    valid = (s > 0) & np.all(np.abs(P[:, :2]) < 3.0, axis=1)
    f = lambda a: a.reshape(H, W, *a.shape[1:]).astype(np.float32)  # noqa: E731
    t = {"depth_z": f(Pc[:, 2]), "range": f(s), "points_world": f(P), "points_cam": f(Pc),
         "normals_world": f(np.tile([0.0, 0.0, 1.0], (len(P), 1))), "normals_cam": f(np.tile(pose.R[:, 2], (len(P), 1))),
         "uv": f(np.zeros((len(P), 2))), "object_id": np.ones((H, W), np.uint32),
         "instance_id": np.ones((H, W), np.uint32), "valid": valid.reshape(H, W)}
    miss = ~t["valid"]
    for k in ("depth_z", "range"):
        t[k][miss] = np.inf
    for k in ("points_world", "points_cam", "normals_world", "normals_cam", "uv"):
        t[k][miss] = np.nan
    t["object_id"][miss] = 0
    t["instance_id"][miss] = 0
    return t


def checker_image(truth: dict) -> np.ndarray:
    P = np.nan_to_num(truth["points_world"])
    g = ((np.floor(P[..., 0] / 0.25) + np.floor(P[..., 1] / 0.25)) % 2) * 150 + 60
    g[~truth["valid"]] = 0
    return np.repeat(g[..., None], 3, axis=2).astype(np.uint8)


def nothing_occludes(center, points) -> np.ndarray:
    """Analytic visibility on the plane: every camera is above it, nothing in between."""
    return np.ones(len(points), bool)


def wire_visibility(center, points) -> np.ndarray:
    """Analytic visibility with the wire: the segment center -> point misses the wire's axis (a
    line along y) by more than its radius (2D distance in the x-z plane)."""
    a = np.array([center[0], center[2]])
    b = np.asarray(points, float)[:, [0, 2]]
    q = np.array([WIRE_X_M, WIRE_HEIGHT_M])
    ab = b - a
    s = np.clip(((q - a) @ ab.T) / np.sum(ab * ab, axis=1), 0.0, 1.0)
    dist = np.linalg.norm(a + s[:, None] * ab - q, axis=1)
    return dist > WIRE_RADIUS_M


def write_plane_dataset(root, *, views=None, visible_fn=nothing_occludes, corr_pairs=None) -> dict:
    """Write the dataset at ``root`` (all views, or the named ones; the correspondence files of every
    ordered pair, or of ``corr_pairs``); return {view: (Camera, cam_from_world)}."""
    w = ds.DatasetWriter(root, spec_sha256="cd" * 32, seed=1, variant="test", versions={"numpy": "x"})
    vcs = {n: vc for n, vc in view_cameras().items() if views is None or n in views}
    w.write_cameras(vcs, {"objects": [{"name": "plane"}]})
    w.write_mesh("plane", trimesh.Trimesh([[-3, -3, 0], [3, -3, 0], [3, 3, 0], [-3, 3, 0]], [[0, 1, 2], [0, 2, 3]],
                                          process=False))
    truths = {}
    for name, vc in vcs.items():
        t = truths[name] = plane_truth(vc.camera, vc.cam_from_world)
        img = checker_image(t)
        w.write_view(name, image=img, linear_rgb=img.astype(np.float32) / 255, truth=t)
    for i in vcs:
        for j in vcs:
            if i != j and (corr_pairs is None or (i, j) in corr_pairs):
                c = correspond(truths[i]["points_world"], vcs[j].camera, vcs[j].cam_from_world, visible_fn)
                w.write_file(correspondence_path(i, j), encode_exr(encode_correspondence_channels(c)))
    return {n: (vc.camera, vc.cam_from_world) for n, vc in vcs.items()}


@pytest.fixture(scope="session")
def plane_dataset(tmp_path_factory):
    """(path, {view: (Camera, cam_from_world)}) of the analytic plane dataset (written once)."""
    root = tmp_path_factory.mktemp("plane") / "ds"
    return root, write_plane_dataset(root)


@pytest.fixture(scope="session")
def occluded_plane_dataset(tmp_path_factory):
    """(path, {view: (Camera, cam_from_world)}) of the stereo rig over the plane with the wire."""
    root = tmp_path_factory.mktemp("wire") / "ds"
    return root, write_plane_dataset(root, views=("left_000", "right_000"), visible_fn=wire_visibility)


@pytest.fixture(scope="session")
def write_plane():
    """``write_plane(root, views=None, visible_fn=..., corr_pairs=None)``: write a variant of the plane dataset."""
    return write_plane_dataset


@pytest.fixture(scope="session")
def plane_scene():
    """The plane dataset's constants: W, H, BASELINE_M, HEIGHT_M, PINHOLE, DISTORTED, the wire's."""
    return types.SimpleNamespace(W=W, H=H, BASELINE_M=BASELINE_M, HEIGHT_M=HEIGHT_M, PINHOLE=PINHOLE,
                                 DISTORTED=DISTORTED, WIRE_COLUMN=WIRE_COLUMN, WIRE_X_M=WIRE_X_M,
                                 WIRE_HEIGHT_M=WIRE_HEIGHT_M, WIRE_RADIUS_M=WIRE_RADIUS_M)


# --- small geometry helpers, as fixtures returning the function ------------------------------------
def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    return Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()


def _look_at_cam_from_world(center, target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)):
    """cam_from_world (R, t) of an OpenCV camera at ``center`` looking at ``target``."""
    c = np.asarray(center, float)
    z = np.asarray(target, float) - c
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    R = np.stack([x, y, z])  # rows: camera axes in world
    return R, -R @ c


def _ring_of_cameras(n: int = 8, radius: float = 3.0, height: float = 1.0):
    """n cameras on a circle looking at the origin: (R (n,3,3), t (n,3)), cam_from_world."""
    Rs, ts = [], []
    for k in range(n):
        a = 2 * np.pi * k / n
        R, t = _look_at_cam_from_world([radius * np.cos(a), radius * np.sin(a), height + 0.1 * k])
        Rs.append(R)
        ts.append(t)
    return np.array(Rs), np.array(ts)


def _num(values) -> str:
    return " ".join(f"{float(v):.17g}" for v in values)


def _write_colmap(d, qs, ts):
    d.mkdir()
    (d / "cameras.txt").write_text("# cams\n1 PINHOLE 640 480 500 505 320 240\n")
    lines = ["# images"]
    for k, (q, t) in enumerate(zip(qs, ts), start=1):
        lines.append(f"{k} {_num(q)} {_num(t)} 1 img{k}.png")
        lines.append("" if k % 2 else "100.0 200.0 -1 5.0 6.0 1")
    (d / "images.txt").write_text("\n".join(lines) + "\n")
    # point 1 is observed by image 2's second keypoint (its POINTS2D line references point 1)
    (d / "points3D.txt").write_text("# pts\n1 0.1 0.2 3.0 255 0 0 0.5 2 1\n")


def _write_feature_result(root, kps: dict, matches: dict):
    """Keypoints and matches in the documented text format (float64 written exactly)."""
    (root / "keypoints").mkdir(parents=True, exist_ok=True)
    (root / "matches").mkdir(parents=True, exist_ok=True)
    for v, xy in kps.items():
        np.savetxt(root / "keypoints" / f"{v}.txt", xy, fmt="%.17g", header="x y")
    for (i, j), m in matches.items():
        np.savetxt(root / "matches" / f"{i}__{j}.txt", m, fmt="%d")
    return root


@pytest.fixture(scope="session")
def write_feature_result():
    """``write_feature_result(root, {view: (N, 2)}, {(i, j): (M, 2)})``: a feature result folder."""
    return _write_feature_result


@pytest.fixture(scope="session")
def random_rotation():
    """``random_rotation(rng)``: a uniformly random (3, 3) rotation."""
    return _random_rotation


@pytest.fixture(scope="session")
def look_at_cam_from_world():
    """``look_at_cam_from_world(center, target=0, up=+z)``: (R, t) cam_from_world, OpenCV axes."""
    return _look_at_cam_from_world


@pytest.fixture(scope="session")
def ring_of_cameras():
    """``ring_of_cameras(n=8, radius=3, height=1)``: (R (n, 3, 3), t (n, 3)) looking at the origin."""
    return _ring_of_cameras


@pytest.fixture(scope="session")
def unit_square():
    """(V (4, 3), F (2, 3)): the unit square in the z = 0 plane as two triangles."""
    return np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]), np.array([[0, 1, 2], [0, 2, 3]])


@pytest.fixture(scope="session")
def numbers_text():
    """``numbers_text(values)``: the values as a line of %.17g numbers (lossless text)."""
    return _num


@pytest.fixture(scope="session")
def write_colmap():
    """``write_colmap(folder, qs, ts)``: a COLMAP text model (PINHOLE 640x480) with these poses."""
    return _write_colmap


#: A poster and a blob seen from a reference view, the same view rolled about its optical axis
#: (one camera centre: no epipolar geometry, nothing to triangulate) and a view 0.6 m to the side;
#: crossview pairs [ref, rolled] and [ref, side] with labelled match sets.
ZERO_BASELINE_SPEC = """
name: zero_baseline_runs
seed: 5
render: {spp: 4, max_depth: 2}
objects:
  - name: poster
    shape: {type: plane, size: [1.6, 1.2]}
    transform: {translation: [0, 0.6, 0.7], rotation_deg: [90, 0, 0]}
    material: {type: diffuse, texture: {type: natural, params: {size_px: 256}}}
  - name: rock
    shape: {type: blob, radius: 0.2}
    transform: {translation: [0.1, 0.1, 0.5]}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam: {size: [120, 90], fx: 100}
views:
  - camera: cam
    look_at:
      - {eye: [0, -1.5, 0.8], target: [0, 0.3, 0.6]}
      - {eye: [0, -1.5, 0.8], target: [0, 0.3, 0.6], up: [0.5, 0, 0.866]}
      - {eye: [0.6, -1.4, 0.9], target: [0, 0.3, 0.6]}
crossview:
  pairs: [[cam_0000, cam_0001], [cam_0000, cam_0002]]
  flow: false
  targets: false
  matches: {count: 200, sigma_px: 0.5, outlier_fraction: 0.2, seed: 3}
"""


@pytest.fixture(scope="session")
def zero_baseline_spec():
    """A spec (YAML text) with a zero-baseline crossview pair and an ordinary one (renders: Mitsuba)."""
    return ZERO_BASELINE_SPEC


# --- a two-frame flow dataset over the plane (no Mitsuba) -------------------------------------------
FLOW_W, FLOW_H = 96, 72
FLOW_CAM = Camera("pinhole", FLOW_W, FLOW_H, 80.0, 80.0, (FLOW_W - 1) / 2, (FLOW_H - 1) / 2)
#: the second frame's camera: moved 0.12 m along x, 0.05 m along y and 0.2 m closer, rolled 2 degrees
FLOW_MOTION = (np.array([0.12, 0.05, -0.2]), 2.0)


def _flow_plane_truth(cam, pose) -> dict:
    uv = np.stack(np.meshgrid(np.arange(cam.width, dtype=float), np.arange(cam.height, dtype=float)), -1).reshape(-1, 2)
    wfc = pose.inverse()
    d = cam.unproject_unit(uv) @ wfc.R.T
    s = -wfc.t[2] / d[:, 2]
    P = wfc.t + s[:, None] * d
    Pc = pose.apply(P)
    f = lambda a: a.reshape(cam.height, cam.width, *a.shape[1:]).astype(np.float32)  # noqa: E731
    n = len(P)
    return {"depth_z": f(Pc[:, 2]), "range": f(s), "points_world": f(P), "points_cam": f(Pc),
            "normals_world": f(np.tile([0.0, 0.0, 1.0], (n, 1))), "normals_cam": f(np.tile(pose.R[:, 2], (n, 1))),
            "uv": f(np.zeros((n, 2))), "object_id": np.ones((cam.height, cam.width), np.uint32),
            "instance_id": np.ones((cam.height, cam.width), np.uint32), "valid": np.ones((cam.height, cam.width), bool)}


def _texture(P) -> np.ndarray:
    """A smooth, well-textured grey pattern on the plane (for the flow estimators)."""
    rng = np.random.default_rng(11)
    k = rng.normal(size=(16, 2))
    k *= (rng.uniform(4.0, 16.0, 16) / np.linalg.norm(k, axis=1))[:, None]  # periods 0.4-1.6 m: 10-40 px
    ph = rng.uniform(0, 2 * np.pi, 16)
    g = 0.5 + 0.09 * np.sum(np.sin(P[..., :2] @ k.T + ph), axis=-1)
    return np.repeat((255 * np.clip(g, 0, 1))[..., None], 3, axis=2).astype(np.uint8)


def write_flow_dataset(root) -> dict:
    """Two frames of camera "cam" over the plane, with flow both ways, the correspondence files of
    the pair and a crossview index (flow pair and crossview pair). Returns {view: (Camera, pose)}."""
    from scenegen.crossview.correspondence import flow_field
    from scenegen.dataset.codecs import encode_flo, encode_json
    from scenegen.dataset.crossview import INDEX_FORMAT, INDEX_FORMAT_VERSION
    from scenegen.dataset.layout import CROSSVIEW_INDEX, flow_path

    w = ds.DatasetWriter(root, spec_sha256="ef" * 32, seed=1, variant="test", versions={"numpy": "x"})
    p0 = Rigid3(DOWN, -DOWN @ np.array([0.0, 0.0, HEIGHT_M]))
    t, roll = FLOW_MOTION
    Rr = Rotation.from_rotvec([0.0, 0.0, np.radians(roll)]).as_matrix()
    p1 = Rigid3(Rr @ DOWN, -(Rr @ DOWN) @ (np.array([0.0, 0.0, HEIGHT_M]) + t))
    vcs = {"cam_000": ds.ViewCamera(FLOW_CAM, p0, "cam", frame_index=0),
           "cam_001": ds.ViewCamera(FLOW_CAM, p1, "cam", frame_index=1)}
    w.write_cameras(vcs, {"objects": [{"name": "plane"}]})
    w.write_mesh("plane", trimesh.Trimesh([[-9, -9, 0], [9, -9, 0], [9, 9, 0], [-9, 9, 0]], [[0, 1, 2], [0, 2, 3]],
                                          process=False))
    truths = {}
    for name, vc in vcs.items():
        tr = truths[name] = _flow_plane_truth(vc.camera, vc.cam_from_world)
        img = _texture(tr["points_world"])
        w.write_view(name, image=img, linear_rgb=img.astype(np.float32) / 255, truth=tr)
    files = []
    for i, j in (("cam_000", "cam_001"), ("cam_001", "cam_000")):
        c = correspond(truths[i]["points_world"], vcs[j].camera, vcs[j].cam_from_world, nothing_occludes)
        w.write_file(correspondence_path(i, j), encode_exr(encode_correspondence_channels(c)))
        w.write_file(flow_path(i, j), encode_flo(flow_field(c)))
        files += [correspondence_path(i, j), flow_path(i, j)]
    index = {"format": INDEX_FORMAT, "format_version": INDEX_FORMAT_VERSION, "occlusion_rel_tol": 1e-4,
             "pairs": [{"i": "cam_000", "j": "cam_001"}], "flow": [{"i": "cam_000", "j": "cam_001"}], "stereo": [],
             "targets": [], "files": sorted(files)}
    w.write_file(CROSSVIEW_INDEX, encode_json(index))
    return {n: (vc.camera, vc.cam_from_world) for n, vc in vcs.items()}


@pytest.fixture(scope="session")
def flow_dataset(tmp_path_factory):
    """(path, {view: (Camera, cam_from_world)}) of the two-frame flow dataset (written once)."""
    root = tmp_path_factory.mktemp("flow") / "ds"
    return root, write_flow_dataset(root)


# --- exact two-view correspondences of a non-planar point set (closed form, no dataset) ------------
def _two_view_points(n: int = 100, seed: int = 0):
    """(x1, x2 (n, 2) exact undistorted pixels, F_gt (3, 3) unit norm, K (3, 3), cam2_from_cam1):
    points in a 1.6 x 1.2 x 1.0 m box seen by wide_baseline.yaml's two cameras (480 x 360, fx 400),
    projected in float64: x2^T F_gt x1 = 0 to rounding."""
    from scenegen.geometry.twoview import fundamental

    rng = np.random.default_rng(seed)
    K = np.array([[400.0, 0.0, 239.5], [0.0, 400.0, 179.5], [0.0, 0.0, 1.0]])
    X = rng.uniform([-0.8, -0.6, -0.5], [0.8, 0.6, 0.5], (n, 3)) + [0.0, 0.3, 0.5]
    p1 = look_at((-0.75, -1.45, 0.9), (0.0, 0.3, 0.5)).inverse()
    p2 = look_at((0.75, -1.45, 0.9), (0.0, 0.3, 0.5)).inverse()
    x1, x2 = (p.apply(X) @ K.T for p in (p1, p2))
    rel = p2 @ p1.inverse()
    return x1[:, :2] / x1[:, 2:], x2[:, :2] / x2[:, 2:], fundamental(K, K, rel), K, rel


@pytest.fixture(scope="session")
def two_view_points():
    """``two_view_points(n=100, seed=0) -> (x1, x2, F_gt, K, cam2_from_cam1)``: exact correspondences."""
    return _two_view_points


# --- structured light ----------------------------------------------------------------------------
# An analytic projector-camera scene (a tilted plane and a sphere in front of it): every camera
# pixel centre's ray hit in closed form, its projector coordinate by the projector's own model,
# the pattern sampled there (scenegen.imaging.patterns.sample); and the same scene written as a
# dataset with projector-lit views (docs/dataset_format.md, "Structured light") for the runners.
SL_PLANE_N = np.array([0.15, -0.1, 1.0]) / np.linalg.norm([0.15, -0.1, 1.0])  # plane n . X = SL_PLANE_D
SL_PLANE_D = 0.6
SL_SPHERE_C = np.array([0.01, 0.0, 0.5])
SL_SPHERE_R = 0.07


@dataclass(frozen=True)
class ProCam:
    camera: Camera
    cam_from_world: Rigid3
    projector: Camera
    proj_from_world: Rigid3
    points: np.ndarray  # (H, W, 3) world points of the pixel centres (NaN: no hit)
    uv: np.ndarray  # (H, W, 2) continuous projector coordinates of the points
    lit: np.ndarray  # (H, W) bool: the projector lights the point
    albedo: np.ndarray  # (H, W)

    def observe(self, seq, *, noise_sigma: float = 0.0, ambient: float = 0.05, seed: int = 0) -> np.ndarray:
        """(N, H, W) grey images of the sequence: albedo * (pattern where lit + ambient) + noise."""
        vals = sample(seq, self.uv).astype(np.float64)  # (N, H, W)
        img = self.albedo[None] * (np.where(self.lit[None], vals, 0.0) + ambient)
        if noise_sigma:
            img = img + np.random.default_rng(seed).normal(0.0, noise_sigma, img.shape)
        return img


def _sl_sphere_t(o, d):
    """Nearest positive ray parameter of rays o + t d (unit d) on the sphere; inf where none."""
    w = np.broadcast_to(o - SL_SPHERE_C, d.shape)
    b = np.einsum("...i,...i->...", d, w)
    disc = b * b - (np.einsum("...i,...i->...", w, w) - SL_SPHERE_R ** 2)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc > 0) & (t > 1e-9), t, np.inf)


def build_procam(camera: Camera, projector: Camera, proj_centre) -> ProCam:
    cam_from_world = Rigid3.identity()
    proj_from_world = look_at(proj_centre, [0.0, 0.0, 0.55], up=(0.0, -1.0, 0.0)).inverse()
    H, W = camera.height, camera.width
    d = camera.unproject_unit(pixel_centers(W, H).reshape(-1, 2))
    o = np.zeros(3)
    t_plane = SL_PLANE_D / (d @ SL_PLANE_N)
    t_sph = _sl_sphere_t(o, d)
    on_sphere = t_sph < t_plane
    t = np.where(on_sphere, t_sph, t_plane)
    p = d * t[:, None]
    # projector visibility: the point's normal faces the projector; nothing (the sphere) between
    pc = np.asarray(proj_centre, float)
    normal = np.where(on_sphere[:, None], (p - SL_SPHERE_C) / SL_SPHERE_R, -SL_PLANE_N)
    to_proj = pc - p
    dist = np.linalg.norm(to_proj, axis=1)
    dir_p = to_proj / dist[:, None]
    blocked = ~on_sphere & (_sl_sphere_t(p + 1e-9 * dir_p, dir_p) < dist)
    uv, ok = projector.project(proj_from_world.apply(p), return_valid=True)
    inside = ok & (uv[:, 0] >= -0.5) & (uv[:, 0] < projector.width - 0.5) & (uv[:, 1] >= -0.5) & \
        (uv[:, 1] < projector.height - 0.5)
    lit = inside & (np.einsum("ij,ij->i", normal, dir_p) > 0) & ~blocked
    albedo = np.where(on_sphere, 0.7, 0.5) + 0.2 * np.cos(40 * p[:, 0])  # textured, 0.3..0.9
    return ProCam(camera, cam_from_world, projector, proj_from_world, p.reshape(H, W, 3), uv.reshape(H, W, 2),
                  lit.reshape(H, W), albedo.reshape(H, W))


@pytest.fixture(scope="session")
def procam() -> ProCam:
    """A 160 x 120 OpenCV camera with distortion, a 128 x 96 projector with distortion, skew and
    an off-centre principal point, 0.15 m apart."""
    camera = Camera("opencv", 160, 120, 150.0, 151.0, 80.3, 59.6, dist=(-0.05, 0.01, 0.001, -0.0005, 0.0))
    projector = Camera("opencv", 128, 96, 140.0, 139.0, 60.0, 70.0, skew=0.4, dist=(0.04, -0.01, 0.0, 0.0, 0.0))
    return build_procam(camera, projector, (0.15, -0.02, 0.0))


def write_sl_dataset(root, pc: ProCam) -> None:
    """One projector-lit view ``scan_0000`` of the analytic scene under the Gray-code sequence,
    in the layout the renderer writes (PNG and linear EXR per pattern, sequence.json, projector truth)."""
    seq = gray_code(pc.projector.width, pc.projector.height)
    H, W = pc.camera.height, pc.camera.width
    w = ds.DatasetWriter(root, spec_sha256="5c" * 32, seed=1, variant="test", versions={"numpy": "x"})
    w.write_cameras({"scan_0000": ds.ViewCamera(pc.camera, pc.cam_from_world, "cam", frame_index=0)},
                    {"objects": [{"name": "plane"}, {"name": "sphere"}]})
    P = pc.points
    Pc = pc.cam_from_world.apply(P)
    n = np.where(np.linalg.norm(P - SL_SPHERE_C, axis=2, keepdims=True) < SL_SPHERE_R + 1e-9,
                 (P - SL_SPHERE_C) / SL_SPHERE_R, -SL_PLANE_N)
    f32 = lambda a: np.asarray(a, np.float32)  # noqa: E731
    truth = {"depth_z": f32(Pc[..., 2]), "range": f32(np.linalg.norm(Pc, axis=2)), "points_world": f32(P),
             "points_cam": f32(Pc), "normals_world": f32(n), "normals_cam": f32(n), "uv": np.zeros((H, W, 2), np.float32),
             "object_id": np.ones((H, W), np.uint32), "instance_id": np.ones((H, W), np.uint32),
             "valid": np.ones((H, W), bool)}
    images = pc.observe(seq)  # (N, H, W) linear
    rgb = lambda k: np.repeat(images[k][..., None], 3, axis=2).astype(np.float32)  # noqa: E731
    srgb = lambda k: np.round(255 * srgb_from_linear(rgb(k))).astype(np.uint8)  # noqa: E731
    entries, extra = [], {}
    for k, fr in enumerate(seq.frames):
        axis = {"u": "columns", "v": "rows"}.get(fr.axis, "")
        bit = fr.n_bits - 1 - fr.bit if fr.bit >= 0 else -1  # the file counts from the least significant bit
        extra[pattern_image_path("scan_0000", k)] = encode_png(srgb(k))
        extra[pattern_linear_path("scan_0000", k)] = encode_exr(pack_channels("", rgb(k), LINEAR_CHANNELS))
        entries.append({"index": k, "name": fr.kind if fr.kind in ("white", "black") else f"{axis[:3]}_bit{bit:02d}",
                        "axis": axis, "bit": bit, "inverse": fr.inverse, "image": pattern_image_path("scan_0000", k),
                        "linear": pattern_linear_path("scan_0000", k)})
    doc = {"format": PATTERNS_FORMAT, "view": "scan_0000",
           "projector": {"name": "proj", "camera": pc.projector.to_dict(),
                         "projector_from_world": pc.proj_from_world.matrix.tolist()},
           "patterns": entries}
    extra[pattern_sequence_path("scan_0000")] = encode_json(doc)
    code = perfect_code(seq, pc.uv)
    lit_code = np.where(pc.lit[..., None], code, -1).astype(np.int32)
    extra[projector_truth_path("scan_0000")] = encode_projector_truth(ProjectorTruth(
        np.where(pc.lit[..., None], pc.uv, np.nan), pc.lit, lit_code[..., 0], lit_code[..., 1],
        np.where(pc.lit, binary_to_gray(lit_code[..., 0]), -1).astype(np.int32),
        np.where(pc.lit, binary_to_gray(lit_code[..., 1]), -1).astype(np.int32), pc.lit, pc.lit))  # point-sampled: clear
    w.write_view("scan_0000", image=srgb(0), linear_rgb=rgb(0), truth=truth, extra_files=extra)
    w.close()


@pytest.fixture(scope="session")
def sl_dataset(tmp_path_factory, procam):
    root = tmp_path_factory.mktemp("sl") / "scan"
    write_sl_dataset(root, procam)
    return root
