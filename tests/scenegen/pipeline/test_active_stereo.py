"""Active IR stereo (scenegen.pipeline.active_stereo): a multi rig of two pinhole IR cameras 50 mm
apart (members left, right) and a random-dot projector, rendered at 64x48. The rectified truth
disparity equals f B / z of an independent trimesh cast; every bit of the IR invalid mask equals
an independent computation (trimesh casts toward the projector and toward the right camera, the
stated depth range); SGBM on the IR pair runs end to end and scores better with the dots on."""
from __future__ import annotations

import shutil

import numpy as np
import pytest
import trimesh

from recon_eval.errors import NotApplicable
from recon_eval.runners import run_method
from scenegen.dataset import Dataset, verify
from scenegen.dataset.ir_stereo import NO_SURFACE, OCCLUDED, OUT_OF_RANGE, SHADOW
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3
from scenegen.imaging import patterns
from scenegen.pipeline.run import render_spec

pytestmark = pytest.mark.render

DEPTH_RANGE = (0.3, 0.75)
ACTIVE = """
seed: 30
render: {spp: 4, max_depth: 2, sampler: ldsampler}
cameras:
  ir: {model: pinhole, size: [64, 48], fx: 44, fy: 44, cx: 31.5, cy: 23.5,
       imaging: {preset: machine_vision, bayer: none}}
projectors:
  dots:
    intrinsics: {model: pinhole, size: [64, 48], fx: 30, fy: 30, cx: 31.5, cy: 23.5}
    intensity_w_sr: 0.6
    patterns: dots
    dots_density: 0.4
lights:
  - {type: constant, radiance: 0.04}
rigs:
  rs:
    type: multi
    members:
      - {camera: ir, name: left}
      - {camera: ir, name: right, rig_from_sensor: {translation: [0.05, 0, 0]}}
      - {kind: projector, sensor: dots, rig_from_sensor: {translation: [-0.06, 0, 0]}}
objects:
  - {name: floor, shape: {type: plane, size: [1.2, 1.2]}, material: {type: diffuse, color: 0.6}}
  - {name: box, shape: {type: box, size: [0.12, 0.12, 0.16]}, transform: {translation: [0.03, 0.02, 0.08]},
     material: {type: diffuse, color: 0.8}}
views:
  - rig: rs
    look_at: [{eye: [0.0, -0.35, 0.45], target: [0.0, 0.05, 0.0]}]
crossview: {pairs: none, flow: false, stereo: true, targets: false, ir_depth_range_m: [0.3, 0.75]}
"""


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    root = tmp_path_factory.mktemp("active")
    spec = root / "active.yaml"
    spec.write_text(ACTIVE)
    out = root / "out"
    render_spec(spec, out, progress=False)
    d = Dataset(out)
    frame = d.crossview.stereo_frames()[0]
    return root, d, frame


def _cast(mesh, origin, dirs):
    """(N,) distance to the first hit along unit ``dirs`` from ``origin`` (inf = none), (N,) face."""
    locs, ray, tri = trimesh.ray.ray_triangle.RayMeshIntersector(mesh).intersects_location(
        np.broadcast_to(origin, dirs.shape), dirs, multiple_hits=True)
    dist = np.linalg.norm(locs - origin, axis=1)
    first, face = np.full(len(dirs), np.inf), np.full(len(dirs), -1)
    order = np.argsort(-dist)  # nearest written last
    first[ray[order]], face[ray[order]] = dist[order], tri[order]
    return first, face


@pytest.fixture(scope="module")
def cast(rendered):
    """The left rectified pixel centres cast with trimesh: z, world points, normals."""
    _, d, frame = rendered
    mesh = trimesh.util.concatenate([d.mesh(n) for n in d.mesh_names])
    cam, cam_from_world = frame.camera, frame.cam_from_world("left")
    v, u = np.mgrid[0:cam.height, 0:cam.width]
    K = cam.K
    rays_cam = np.stack([(u - K[0, 2]) / K[0, 0], (v - K[1, 2]) / K[1, 1], np.ones(u.shape)], -1).reshape(-1, 3)
    world_from_cam = cam_from_world.inverse()
    dirs = world_from_cam.R @ (rays_cam / np.linalg.norm(rays_cam, axis=1, keepdims=True)).T
    dist, face = _cast(mesh, world_from_cam.t, dirs.T)
    P = world_from_cam.t + dirs.T * dist[:, None]
    z = cam_from_world.apply(np.where(np.isfinite(P), P, 0.0))[:, 2]
    return mesh, np.where(np.isfinite(dist), z, np.nan).reshape(cam.height, cam.width), P, mesh.face_normals[face]


def test_the_rig_writes_an_active_frame(rendered):
    _, d, frame = rendered
    assert verify(d.root).ok
    assert frame.baseline_m == pytest.approx(0.05, abs=1e-12)
    on, off = frame.ir_image("left"), frame.ir_image("left", projector=False)
    assert on.shape == off.shape == (48, 64) and on.dtype == np.uint8
    assert on.mean() > off.mean() + 5 and on.std() > 2 * off.std()  # the dots: light and texture


def test_truth_disparity_is_f_b_over_z_of_a_trimesh_cast(rendered, cast):
    _, d, frame = rendered
    _, z, _, _ = cast
    disp = frame.disparity("left").astype(np.float64)
    f = frame.camera.fx
    assert np.array_equal(np.isfinite(disp), np.isfinite(z))
    ok = np.isfinite(z)
    assert ok.sum() > 2000
    rel = np.abs(disp[ok] - f * 0.05 / z[ok]) / (f * 0.05 / z[ok])
    assert rel.max() < 1e-5, rel.max()  # float32 storage of the truth


def test_invalid_mask_bits_equal_an_independent_computation(rendered, cast):
    root, d, frame = rendered
    mesh, z, P, n = cast
    bits = frame.ir_invalid("left").ravel().astype(int)
    ok = np.isfinite(z).ravel()
    assert np.array_equal(bits == NO_SURFACE, ~ok)
    seq = d.pattern_sequence(frame.left_view)
    proj = Camera.from_dict(seq["projector"]["camera"])
    proj_from_world = Rigid3.from_matrix(np.array(seq["projector"]["projector_from_world"]))
    C_cam = frame.cam_from_world("left").inverse().t

    def blocked(centre, pts):
        dirs = pts - centre
        dist = np.linalg.norm(dirs, axis=1)
        first, _ = _cast(mesh, centre, dirs / dist[:, None])
        return first < dist * (1 - 1e-4)  # something before the point (its own surface aside)

    idx = np.flatnonzero(ok)
    Pp = proj_from_world.apply(P[idx])
    uv = np.stack([proj.fx * Pp[:, 0] / Pp[:, 2] + proj.cx, proj.fy * Pp[:, 1] / Pp[:, 2] + proj.cy], 1)
    inside = (Pp[:, 2] > 0) & np.all((np.floor(uv + 0.5) >= 0) & (np.floor(uv + 0.5) < [proj.width, proj.height]), 1)
    C_proj = proj_from_world.inverse().t
    facing = np.sign(np.einsum("ij,ij->i", n[idx], C_cam - P[idx])) * np.einsum("ij,ij->i", n[idx], C_proj - P[idx]) > 0
    shadow = ~(inside & facing & ~blocked(C_proj, P[idx]))
    right = frame.cam_from_world("right")
    Pr = right.apply(P[idx])
    ur = np.stack([frame.camera.fx * Pr[:, 0] / Pr[:, 2] + frame.camera.cx,
                   frame.camera.fy * Pr[:, 1] / Pr[:, 2] + frame.camera.cy], 1)
    in_right = (Pr[:, 2] > 0) & np.all((ur >= -0.5) & (ur < np.array([64, 48]) - 0.5), 1)
    occluded = ~(in_right & ~blocked(right.inverse().t, P[idx]))
    out_range = (z.ravel()[idx] < DEPTH_RANGE[0]) | (z.ravel()[idx] > DEPTH_RANGE[1])
    for bit, expected in ((SHADOW, shadow), (OCCLUDED, occluded), (OUT_OF_RANGE, out_range)):
        got = (bits[idx] & bit) > 0
        assert 20 < expected.sum() < len(idx) - 20, bit  # the scene exercises the category both ways
        assert np.array_equal(got, expected), (bit, np.flatnonzero(got != expected))


def test_the_ir_image_shows_the_dots_where_the_truth_puts_them(rendered, cast):
    """The dot each lit pixel's (trimesh) surface point receives, by projecting it through the
    projector, is what the rendered IR pair shows there: the image and the truth agree on the
    projector's pose and pattern."""
    _, d, frame = rendered
    _, z, P, _ = cast
    seq = d.pattern_sequence(frame.left_view)
    proj = Camera.from_dict(seq["projector"]["camera"])
    proj_from_world = Rigid3.from_matrix(np.array(seq["projector"]["projector_from_world"]))
    e = seq["patterns"][0]
    dots = patterns.random_dots(proj.width, proj.height, seed=e["seed"], density=e["density"], dot_px=e["dot_px"])
    ok = np.isfinite(z).ravel()
    uv = np.full((len(P), 2), np.nan)
    uv[ok] = proj.project(proj_from_world.apply(P[ok]))
    value = patterns.sample(dots, uv)[0]
    lit = ok & ((frame.ir_invalid("left").ravel() & SHADOW) == 0)
    ir = frame.ir_image("left").ravel().astype(float)
    on, off = ir[lit & (value == 1)], ir[lit & (value == 0)]
    assert len(on) > 300 and len(off) > 300
    assert np.median(on) > np.median(off) + 20 and np.mean(on > np.median(off)) > 0.9, (np.median(on), np.median(off))


def test_sgbm_on_the_ir_pair_end_to_end(rendered):
    root, d, _ = rendered
    res = {m: run_method(m, d.root, root / m) for m in ("opencv-sgbm-ir", "opencv-sgbm-ir-off")}
    on, off = (res[m]["metrics"] for m in ("opencv-sgbm-ir", "opencv-sgbm-ir-off"))
    assert 0 < on["valid_px_pct"] == off["valid_px_pct"] < 100
    assert (root / "opencv-sgbm-ir" / "disparity").is_dir()
    print({k: (on[k], off[k]) for k in ("bad_2_0_valid_pct", "invalid_valid_pct", "bad_2_0_noc_pct")})
    # the dots give the matcher texture: more estimates, fewer wrong ones
    assert on["invalid_valid_pct"] < off["invalid_valid_pct"] and on["bad_2_0_valid_pct"] < off["bad_2_0_valid_pct"]


def test_a_passive_stereo_frame_is_not_applicable(rendered):
    root, d, _ = rendered
    passive = root / "passive"
    shutil.copytree(d.root, passive, ignore=shutil.ignore_patterns("ir_*.png"))
    with pytest.raises(NotApplicable, match="has no IR pair"):
        run_method("opencv-sgbm-ir", passive, root / "passive_run")
