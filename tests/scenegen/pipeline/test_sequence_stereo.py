"""A stereo rig's truth across time on the rectified grid (KITTI 2015 scene flow) and the Sintel
export, against an independent derivation: a moving, verged stereo rig (80x60 pinholes) over a
floor, a moving sphere, a moving and turning box and a box that appears late. The test places
the rig and its cameras itself (numpy lerp + scipy Slerp of its own look-at keyframes), rectifies
with cv2.stereoRectify, casts every rectified pixel's ray against the analytic geometry itself
(no Mitsuba, no scenegen camera, pose or rectification code), moves the hit point with its own
object poses, projects with cv2.projectPoints and decides visibility by its own first-hit casts
from both rectified centres in frame b's scene. The KITTI PNGs are read back with the devkit's
decoding rules written out here (readme.txt, "Data format"), the Sintel files with readers
written from the Sintel SDK's sintel_io.py (depth_read, cam_read, flow_read)."""
import json
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.dataset.codecs import read_exr, read_json
from scenegen.dataset.crossview import NO_SURFACE, OCCLUDED, OUT_OF_FRAME, VISIBLE
from scenegen.pipeline.run import render_spec

sys.path.insert(0, str(Path(__file__).parent))
from analytic_scene import SEQUENCE_SCENE, look, slerp_lerp  # noqa: E402

pytestmark = [pytest.mark.render, pytest.mark.filterwarnings("ignore:invalid value:RuntimeWarning")]

W, H, F = 80, 60, 70.0
K = np.array([[F, 0, (W - 1) / 2], [0, F, (H - 1) / 2], [0, 0, 1.0]])
BASELINE, VERGENCE_DEG = 0.25, 4.0
TIMES = [0.0, 0.1, 0.2]
REL_TOL = 1e-4  # the dataset's OCCLUSION_REL_TOL, restated as the independent cast's rule
# Flow, px: the dataset's point comes from a float32 ray hit (relative error ~1e-7 of its ~2 m
# distance) moved and projected in float64, then stored as float32 (~4e-6 px at 30 px); the raw
# cameras' flow agrees to 4.6e-5 px (test_sequence_truth.py). Measured here: max 2.9e-5 px.
TOL_FLOW_PX = 2e-4
# Depth at b, m: the same float32 hit error, which grows along grazing floor rays (1 / cos of the
# incidence) to ~1e-6 m, plus float32 storage (~1.2e-7 m at 2 m); measured max 1.4e-6 m. Scene
# flow (float64 differences of those points, float32 stored): measured 6.9e-7 m. Disparity
# f B / z (~9 px) inherits z's relative error: measured max 6.5e-6 px.
TOL_Z_M = 5e-6
TOL_SCENE_FLOW_M = 3e-6
TOL_DISP_PX = 2e-5
# Grazing silhouette pixels may hit another object in float32 than in float64 (left out, rare:
# none measured); states may differ only where another surface lies 0.1x to 10x the tolerance in
# front of the point (none measured; 0-2 such pixels per pair, out of ~3,900).
MAX_ID_MISMATCH = 0.01
MAX_STATE_MISMATCH = 0.002
# KITTI PNG quantisation: disparity round(d * 256) -> |error| <= 1/512 px; flow: the devkit's
# writeFlowField truncates f * 64 + 2^15 in float32 -> decoded in (f - 1/64, f], give or take the
# float32 sum's rounding at 2^15 (2^-8 of a unit: 6.1e-5 px); both bounds get TOL_FLOW_PX on top
# for the truth's own error against the independent value.
KITTI_DISP_Q = 1 / 512 + TOL_DISP_PX
KITTI_FLOW_Q = 1 / 64

SPEC = f"""
name: seqstereo
render: {{spp: 1, max_depth: 2}}
sequence: {{fps: 10, frames: 3, flow_steps: [1, 2]}}
objects:
  - name: floor
    shape: {{type: plane, size: [4, 4]}}
  - name: ball
    shape: {{type: sphere, radius: 0.25}}
    trajectory:
      interpolation: linear
      keyframes:
        - {{time_s: 0.0, translation: [-0.3, 0.1, 0.25]}}
        - {{time_s: 0.2, translation: [0.3, -0.1, 0.35], rotation_deg: [0, 0, 40]}}
  - name: crate
    shape: {{type: box, size: [0.3, 0.2, 0.25]}}
    trajectory:
      interpolation: linear
      keyframes:
        - {{time_s: 0.0, translation: [0.35, 0.3, 0.125], rotation_deg: [0, 0, 10]}}
        - {{time_s: 0.2, translation: [-0.2, 0.25, 0.2], rotation_deg: [20, 0, 80]}}
  - name: dice
    shape: {{type: box, size: [0.15, 0.15, 0.15]}}
    visible_s: [0.15, 1.0]
    trajectory: {{keyframes: [{{time_s: 0.0, translation: [-0.45, -0.35, 0.075]}}]}}
lights: [{{type: constant, radiance: 1}}]
cameras: {{cam: {{size: [{W}, {H}], fx: {F}}}}}
rigs: {{st: {{type: stereo, left: cam, right: cam, baseline_m: {BASELINE}, vergence_deg: {VERGENCE_DEG}}}}}
views:
  - rig: st
    trajectory:
      interpolation: linear
      keyframes:
        - {{time_s: 0.0, eye: [0.1, -1.8, 1.3], target: [0, 0, 0.1]}}
        - {{time_s: 0.2, eye: [-0.25, -1.7, 1.4], target: [0, 0.05, 0.1]}}
crossview: {{pairs: none, flow: false, stereo: true}}
"""


# --- the independent derivation --------------------------------------------------------------
SCENE = SEQUENCE_SCENE  # the spec's objects, restated (tests/scenegen/pipeline/analytic_scene.py)
IDS = SCENE.ids
RIG_PATH = (0.0, 0.2, look([0.1, -1.8, 1.3], [0, 0, 0.1]), look([-0.25, -1.7, 1.4], [0, 0.05, 0.1]),
            [0.1, -1.8, 1.3], [-0.25, -1.7, 1.4])


def world_from(name, t):
    """(R, centre) of an object or of the rig frame at time t, interpolated here."""
    if name == "rig":
        R, c = slerp_lerp(t, *RIG_PATH)
        return R[0], c[0]
    return SCENE.pose(name, t)


def dice_present(t):
    return bool(SCENE.present("dice", t)[0])


def first_hits(o, d, t):
    """(N,) distance along unit rays o + s d to the first hit and (N,) object id (float64)."""
    return SCENE.first_hits(o, d, t)


def _ry(deg):
    return Rotation.from_euler("y", deg, degrees=True).as_matrix()


def raw_cameras(t):
    """{side: (cam_from_world R, centre)} of the rig's members: the left centre is the rig origin,
    the right one at +baseline along the rig's x; toe-in Ry(+v/2) left, Ry(-v/2) right."""
    Rr, C = world_from("rig", t)
    return {"left": ((Rr @ _ry(VERGENCE_DEG / 2)).T, C),
            "right": ((Rr @ _ry(-VERGENCE_DEG / 2)).T, C + Rr @ [BASELINE, 0, 0])}


def rectified(t):
    """cv2.stereoRectify of the raw pair at t: (K_rect, f, baseline, {side: (R, centre)})."""
    cams = raw_cameras(t)
    (Rl, Cl), (Rr, Cr) = cams["left"], cams["right"]
    R, T = Rr @ Rl.T, Rr @ (Cl - Cr)  # right_from_left
    R1, R2, P1, P2, *_ = cv2.stereoRectify(K, np.zeros(5), K, np.zeros(5), (W, H), R, T,
                                           flags=cv2.CALIB_ZERO_DISPARITY, alpha=-1)
    return P1[:, :3], P1[0, 0], -P2[0, 3] / P2[0, 0], {"left": (R1 @ Rl, Cl), "right": (R2 @ Rr, Cr)}


def pixel_rays(K_rect, R):
    u, v = np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float))
    d = np.stack([u.ravel(), v.ravel(), np.ones(W * H)], 1) @ np.linalg.inv(K_rect).T
    d = d @ R  # R^T d per row: world directions
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def project(P, K_rect, R, C):
    rvec, _ = cv2.Rodrigues(R)
    uv, _ = cv2.projectPoints(P.reshape(-1, 1, 3), rvec, -R @ C, K_rect, None)
    return uv.reshape(-1, 2), (P - C) @ R[2]


def moved(P, ids, ta, tb):
    return SCENE.moved(P, ids, ta, tb)


def state_in(P, present, K_rect, R, C, t):
    """(uv, z, state, ambiguous) of world points seen by a rectified camera at time t."""
    uv, z = project(P, K_rect, R, C)
    inside = (z > 0) & (uv[:, 0] >= -0.5) & (uv[:, 0] <= W - 0.5) & (uv[:, 1] >= -0.5) & (uv[:, 1] <= H - 0.5)
    dist = np.linalg.norm(P - C, axis=1)
    s, _ = first_hits(C, (P - C) / dist[:, None], t)
    visible = (s >= dist * (1 - REL_TOL)) & present
    state = np.where(inside, np.where(visible, VISIBLE, OCCLUDED), OUT_OF_FRAME)
    # ambiguous: another surface's first hit lies in front of the point by 0.1x to 10x the
    # tolerance, where the dataset's float32 point may be decided either way (the point itself is
    # hit at dist - s ~ 1e-15 dist here, a real occluder farther in front)
    gap = dist - s
    return uv, z, state, (gap > 0.1 * REL_TOL * dist) & (gap < 10 * REL_TOL * dist)


def independent(ka, kb):
    """The independent truth of the rectified left pixels of frame ka at frame kb."""
    ta, tb = TIMES[ka], TIMES[kb]
    Ka, fa, Ba, cams_a = rectified(ta)
    Kb, fb, Bb, cams_b = rectified(tb)
    Ra, Ca = cams_a["left"]
    d = pixel_rays(Ka, Ra)
    s, ids = first_hits(Ca, d, ta)
    Pa = Ca + s[:, None] * d
    _, za = project(Pa, Ka, Ra, Ca)
    _, _, state_ra, amb_ra = state_in(Pa, np.ones(len(Pa), bool), Ka, *cams_a["right"], ta)
    Pb = moved(Pa, ids, ta, tb)
    present = ~((ids == IDS["dice"]) & (not dice_present(tb)))
    uv, zb, state_l, amb_l = state_in(Pb, present, Kb, *cams_b["left"], tb)
    _, _, state_r, amb_r = state_in(Pb, present, Kb, *cams_b["right"], tb)
    grid = np.stack(np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float)), -1).reshape(-1, 2)
    return dict(ids=ids, d0=fa * Ba / za, state_right_a=state_ra, flow=uv - grid, z=zb, d1=fb * Bb / zb,
                state_left=state_l, state_right=state_r, ambiguous=amb_ra | amb_l | amb_r, Pa=Pa, Pb=Pb)


# --- the dataset ------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("seqstereo")
    (root / "scene.yaml").write_text(SPEC)
    render_spec(root / "scene.yaml", root / "out", progress=False)
    return root / "out"


def _object_ids(dataset, k):
    """(H * W,) object ids of frame k's rectified left view, as the stereo stage stored them."""
    return read_exr(dataset / f"crossview/stereo/st_left_{k:04d}/ids_left.exr")["object_id"].reshape(-1)


@pytest.fixture(scope="module")
def kitti(dataset, tmp_path_factory):
    dest = tmp_path_factory.mktemp("kitti") / "k"
    assert main(["export", str(dataset), "--format", "kitti-sceneflow", "-o", str(dest), "-q"]) == 0
    return dest


def test_the_rectification_is_opencvs(dataset):
    for k, t in enumerate(TIMES):
        calib = read_json(dataset / f"crossview/stereo/st_left_{k:04d}/calib.json")
        K_rect, f, B, cams = rectified(t)
        R, C = cams["left"]
        pose = calib["cam_left_from_world"]
        assert np.abs(np.array(calib["K"]) - K_rect).max() < 1e-9
        assert abs(calib["baseline_m"] - B) < 1e-12 and abs(np.array(calib["P2"])[0, 3] + f * B) < 1e-9
        assert np.abs(np.array(pose["R"]) - R).max() < 1e-12
        assert np.abs(np.array(pose["t"]) + R @ C).max() < 1e-12


@pytest.mark.parametrize("ka,kb", [(0, 1), (1, 0), (1, 2), (0, 2), (2, 0)])
def test_stereo_motion_matches_the_independent_derivation(dataset, ka, kb):
    want = independent(ka, kb)
    ds = Dataset(dataset)
    m = ds.sequence.stereo_motion(f"st_left_{ka:04d}", f"st_left_{kb:04d}")
    truth_ids = _object_ids(dataset, ka)
    assert (want["ids"] != truth_ids).mean() < MAX_ID_MISMATCH
    same = (want["ids"] == truth_ids) & (want["ids"] > 0)
    flow, z, d1 = m.flow.reshape(-1, 2), m.left.correspondence.z.reshape(-1), m.disparity.reshape(-1)
    sf = m.left.scene_flow.reshape(-1, 3)
    err_flow = np.abs(flow[same] - want["flow"][same]).max()
    err_z = np.abs(z[same] - want["z"][same]).max()
    err_d = np.abs(d1[same] - want["d1"][same]).max()
    err_sf = np.abs(sf[same] - (want["Pb"] - want["Pa"])[same]).max()
    print(f"{ka}->{kb}: flow {err_flow:.2e} px, z {err_z:.2e} m, d1 {err_d:.2e} px, scene flow {err_sf:.2e} m")
    assert err_flow < TOL_FLOW_PX and err_z < TOL_Z_M and err_d < TOL_DISP_PX and err_sf < TOL_SCENE_FLOW_M
    for got, key in ((m.state.reshape(-1), "state_left"), (m.state_right.reshape(-1), "state_right")):
        assert np.all(got[truth_ids == 0] == NO_SURFACE)
        differ = same & (got != want[key])
        print(f"{ka}->{kb} {key}: {differ.sum()} of {same.sum()} differ ({want['ambiguous'].sum()} ambiguous);"
              f" occluded {np.sum(want[key][same] == OCCLUDED)},"
              f" out of frame {np.sum(want[key][same] == OUT_OF_FRAME)}")
        assert np.all(want["ambiguous"][differ]) and differ.mean() <= MAX_STATE_MISMATCH
        assert np.sum(want[key][same] == OCCLUDED) > 20 and np.sum(want[key][same] == OUT_OF_FRAME) > 20


def _kitti_disp(path):
    """The devkit's rule: disp = I / 256.0, valid = I > 0 (uint16 grey PNG)."""
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    assert img.dtype == np.uint16 and img.shape == (H, W)
    return img.astype(np.float64).reshape(-1) / 256.0, img.reshape(-1) > 0


def _kitti_flow(path):
    """The devkit's rule: u = (I1 - 2^15) / 64, v = (I2 - 2^15) / 64, valid = I3 (16-bit RGB)."""
    bgr = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    assert bgr.dtype == np.uint16 and bgr.shape == (H, W, 3)
    rgb = bgr[..., ::-1].reshape(-1, 3).astype(np.float64)
    return (rgb[:, :2] - 2 ** 15) / 64.0, rgb[:, 2] > 0


@pytest.mark.parametrize("k", [0, 1])
def test_kitti_sceneflow_reads_back_as_the_independent_truth(dataset, kitti, k):
    want = independent(k, k + 1)
    ds = Dataset(dataset)
    truth_ids = _object_ids(dataset, k)
    sure = (want["ids"] == truth_ids) & ~want["ambiguous"]  # the pixels both casts agree on
    surface = want["ids"] > 0
    tr = kitti / "training"
    d0_occ, v0_occ = _kitti_disp(tr / f"disp_occ_0/{k:06d}_10.png")
    _, v0_noc = _kitti_disp(tr / f"disp_noc_0/{k:06d}_10.png")
    d1_occ, v1_occ = _kitti_disp(tr / f"disp_occ_1/{k:06d}_10.png")
    d1_noc, v1_noc = _kitti_disp(tr / f"disp_noc_1/{k:06d}_10.png")
    f_occ, vf_occ = _kitti_flow(tr / f"flow_occ/{k:06d}_10.png")
    f_noc, vf_noc = _kitti_flow(tr / f"flow_noc/{k:06d}_10.png")
    projects = surface & (want["z"] > 0)
    masks = {"disp_occ_0": (v0_occ, surface), "disp_noc_0": (v0_noc, want["state_right_a"] == VISIBLE),
             "disp_occ_1": (v1_occ, projects),
             "disp_noc_1": (v1_noc, (want["state_left"] == VISIBLE) & (want["state_right"] == VISIBLE)),
             "flow_occ": (vf_occ, projects), "flow_noc": (vf_noc, want["state_left"] == VISIBLE)}
    for key, (got, expected) in masks.items():
        assert np.array_equal(got[sure], (expected & surface)[sure]), key
        assert got.sum() > 0.3 * W * H, key
    assert v0_noc.sum() < v0_occ.sum() and v1_noc.sum() < v1_occ.sum() and vf_noc.sum() < vf_occ.sum()
    ok0, ok1, okf = v0_occ & sure, v1_occ & sure, vf_occ & sure
    e0 = np.abs(d0_occ[ok0] - want["d0"][ok0]).max()
    e1 = np.abs(d1_occ[ok1] - want["d1"][ok1]).max()
    ef = f_occ[okf] - want["flow"][okf]
    print(f"pair {k}: masks compared on {sure.sum()} of {sure.size} pixels; d0 {e0:.2e} px, d1 {e1:.2e} px,"
          f" flow [{ef.min():.2e}, {ef.max():.2e}] px")
    assert e0 <= KITTI_DISP_Q and e1 <= KITTI_DISP_Q
    assert ef.min() > -KITTI_FLOW_Q - TOL_FLOW_PX and ef.max() < TOL_FLOW_PX
    assert np.array_equal(f_noc[vf_noc], f_occ[vf_noc]) and np.array_equal(d1_noc[v1_noc], d1_occ[v1_noc])
    # the four images are the rectified frames; obj_map and calib those of frame a
    for folder, side in (("image_2", "left"), ("image_3", "right")):
        for suffix, frame in (("10", k), ("11", k + 1)):
            img = cv2.imread(str(tr / f"{folder}/{k:06d}_{suffix}.png"))[..., ::-1]
            assert np.array_equal(img, ds.crossview.stereo(f"st_left_{frame:04d}").image(side))
    obj = cv2.imread(str(tr / f"obj_map/{k:06d}_10.png"), cv2.IMREAD_UNCHANGED).reshape(-1)
    fr = ds.crossview.stereo(f"st_left_{k:04d}")
    moving = np.isin(fr.object_ids("left").reshape(-1), [IDS["ball"], IDS["crate"], IDS["dice"]])  # the floor stays
    assert np.array_equal(obj, np.where(moving, fr.instance_ids("left").reshape(-1), 0))
    assert moving.any() and (~moving & (obj == 0)).any()
    calib = dict(line.split(": ", 1) for line in (tr / f"calib_cam_to_cam/{k:06d}.txt").read_text().splitlines())
    K_rect, f, B, _ = rectified(TIMES[k])
    P3 = np.array(calib["P_rect_03"].split(), float).reshape(3, 4)
    assert np.abs(P3[:, :3] - K_rect).max() < 1e-9 and abs(P3[0, 3] + f * B) < 1e-9


def test_kitti_sceneflow_pairs_are_the_forward_step_1_pairs(kitti):
    pairs = read_json(kitti / "pairs.json")["pairs"]
    assert [(p["a"]["left_view"], p["b"]["left_view"]) for p in pairs] == [("st_left_0000", "st_left_0001"),
                                                                          ("st_left_0001", "st_left_0002")]
    assert pairs[0]["a"]["right_view"] == "st_right_0000"


# --- Sintel -----------------------------------------------------------------------------------
TAG_FLOAT = 202021.25


def _sintel_depth_read(path):
    with open(path, "rb") as f:
        assert np.fromfile(f, np.float32, 1)[0] == TAG_FLOAT
        w, h = np.fromfile(f, np.int32, 1)[0], np.fromfile(f, np.int32, 1)[0]
        return np.fromfile(f, np.float32, -1).reshape(h, w)


def _sintel_cam_read(path):
    with open(path, "rb") as f:
        assert np.fromfile(f, np.float32, 1)[0] == TAG_FLOAT
        return np.fromfile(f, "float64", 9).reshape(3, 3), np.fromfile(f, "float64", 12).reshape(3, 4)


def _sintel_flow_read(path):
    with open(path, "rb") as f:
        assert np.fromfile(f, np.float32, 1)[0] == TAG_FLOAT
        w, h = np.fromfile(f, np.int32, 1)[0], np.fromfile(f, np.int32, 1)[0]
        tmp = np.fromfile(f, np.float32, -1).reshape(h, w * 2)
        return tmp[:, np.arange(w) * 2], tmp[:, np.arange(w) * 2 + 1]


def test_sintel_export_reads_back_with_the_sdk_rules(dataset, tmp_path):
    assert main(["export", str(dataset), "--format", "sintel", "-o", str(tmp_path / "s"), "-q"]) == 0
    ds = Dataset(dataset)
    tr = tmp_path / "s/training"
    u, v = np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float))
    worst_point = 0.0
    for side in ("left", "right"):
        for k, t in enumerate(TIMES):
            frame, view = f"st_{side}/frame_{k + 1:04d}", f"st_{side}_{k:04d}"
            M, N = _sintel_cam_read(tr / f"camdata_left/{frame}.cam")
            R, C = raw_cameras(t)[side]
            assert np.abs(M - K).max() < 1e-12 and np.abs(N[:, :3] - R).max() < 1e-12
            assert np.abs(N[:, 3] + R @ C).max() < 1e-12
            depth = _sintel_depth_read(tr / f"depth/{frame}.dpt")
            truth = ds.truth(view)
            assert np.array_equal(depth, np.where(truth["valid"], truth["depth_z"], 0).astype(np.float32))
            # z-depth: x = M N X back-projects to the analytic first hit along the pixel's ray
            X_cam = np.stack([u, v, np.ones_like(u)], -1).reshape(-1, 3) @ np.linalg.inv(M).T * depth.reshape(-1, 1)
            X = (X_cam - N[:, 3]) @ N[:, :3]
            d = (X_cam / np.linalg.norm(X_cam, axis=1, keepdims=True)) @ R
            s, _ = first_hits(C, d, t)
            ok = depth.reshape(-1) > 0
            worst_point = max(worst_point, float(np.abs(X[ok] - (C + s[ok, None] * d[ok])).max()))
            img = cv2.imread(str(tr / f"final/{frame}.png"))[..., ::-1]
            assert np.array_equal(img, ds.image(view))
            if k == len(TIMES) - 1:
                assert not (tr / f"flow/{frame}.flo").exists()
                continue
            fu, fv = _sintel_flow_read(tr / f"flow/{frame}.flo")
            m = ds.sequence.motion(view, f"st_{side}_{k + 1:04d}")
            flo = ds.sequence.flow(view, f"st_{side}_{k + 1:04d}")  # the dataset's own .flo, decoded
            known = np.isfinite(m.flow[..., 0])
            assert np.array_equal(np.abs(fu) < 1e9, known) and np.array_equal(np.isfinite(flo[..., 0]), known)
            assert np.array_equal(np.stack([fu, fv], -1)[known], flo[known])
            occ = cv2.imread(str(tr / f"occlusions/{frame}.png"), cv2.IMREAD_UNCHANGED)
            inv = cv2.imread(str(tr / f"invalid/{frame}.png"), cv2.IMREAD_UNCHANGED)
            assert occ.dtype == np.uint8 and set(np.unique(occ)) == {0, 255}
            assert np.array_equal(occ == 255, truth["valid"] & (m.state != VISIBLE))
            assert np.array_equal(inv == 255, ~known)
    print(f"sintel: depth back-projected through M, N lands on the analytic hit within {worst_point:.2e} m")
    assert worst_point < 1e-5  # float32 depth of ~2 m: 1.2e-7 m rounding, plus the float32 hit


def test_sequence_stereo_truth_is_deterministic_and_resumable(dataset, tmp_path):
    (tmp_path / "s.yaml").write_text(SPEC)
    out = tmp_path / "r"
    assert main(["render", str(tmp_path / "s.yaml"), "-o", str(out), "-q", "--frames", "1"]) == 0
    assert main(["render", str(tmp_path / "s.yaml"), "-o", str(out), "-q", "--resume", "--frames", "0-2"]) == 0
    a = json.loads((dataset / "manifest.json").read_text())["files"]
    b = json.loads((out / "manifest.json").read_text())["files"]
    assert a == b and "sequence/stereo_motion/st_left_0001/st_left_0000.exr" in a
    index = read_json(dataset / "sequence/index.json")
    assert index["stereo_pairs"] == [{"a": "st_left_0000", "b": "st_left_0001", "step": 1},
                                     {"a": "st_left_0001", "b": "st_left_0002", "step": 1},
                                     {"a": "st_left_0000", "b": "st_left_0002", "step": 2}]


DISTORTED = """
name: seqdistorted
render: {spp: 1, max_depth: 2}
sequence: {fps: 10, frames: 2}
objects:
  - name: floor
    shape: {type: plane, size: [4, 4]}
lights: [{type: constant, radiance: 1}]
cameras: {lens: {model: opencv, size: [24, 18], fx: 20, dist: [-0.1, 0.01, 0, 0]}}
views:
  - camera: lens
    trajectory:
      keyframes: [{time_s: 0, eye: [0, -2, 1.5], target: [0, 0, 0]}, {time_s: 0.1, eye: [0.1, -2, 1.5], target: [0, 0, 0]}]
"""


def test_exports_that_cannot_be_made_are_refused_in_one_line(dataset, tmp_path, capsys):
    (tmp_path / "d.yaml").write_text(DISTORTED)
    assert main(["render", str(tmp_path / "d.yaml"), "-o", str(tmp_path / "d"), "-q"]) == 0
    capsys.readouterr()
    assert main(["export", str(tmp_path / "d"), "--format", "sintel", "-o", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "camera 'lens'" in err and "'opencv' camera" in err and "pinhole" in err and "Traceback" not in err
    assert main(["export", str(tmp_path / "d"), "--format", "kitti-sceneflow", "-o", str(tmp_path / "k")]) == 2
    err = capsys.readouterr().err
    assert "no stereo scene flow with step 1" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "s").exists() and not (tmp_path / "k").exists()
    assert not list(tmp_path.glob(".*partial*"))
