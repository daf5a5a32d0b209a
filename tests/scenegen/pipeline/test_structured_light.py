"""A camera and a distorted, skewed projector in one rig (scenegen.pipeline.structured_light):
rendered at 48x36 under the projector's column Gray codes (14 patterns), verified; the stored
projector pixel of every camera pixel equals OpenCV's projection of the stored truth point, the
projector-shadow mask equals an independent trimesh ray cast, and a plain Gray-code decode of the
rendered patterns reads the truth codes."""
from __future__ import annotations

import cv2
import numpy as np
import pytest
import trimesh

from scenegen.dataset import Dataset, verify
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3
from scenegen.pipeline.run import render_spec

pytestmark = pytest.mark.render

PROCAM = """
seed: 5
render: {spp: 4, max_depth: 2, sampler: ldsampler}
cameras:
  cam: {model: opencv, size: [48, 36], fx: 60, fy: 61, cx: 23.2, cy: 17.9, dist: [-0.1, 0.02, 0.001, -0.001, 0.0]}
projectors:
  proj:
    intrinsics: {model: opencv, size: [40, 30], fx: 30, fy: 31, cx: 21.3, cy: 12.2, skew: 1.5,
                 dist: [-0.08, 0.01, 0.002, -0.003, 0.0]}
    intensity_w_sr: 1.0
    pattern_axes: columns
lights:
  - {type: constant, radiance: 0.01}
rigs:
  procam:
    type: multi
    members:
      - {camera: cam}
      - {kind: projector, sensor: proj, rig_from_sensor: {translation: [0.4, 0, 0], rotation_deg: [-4, -22, 0]}}
objects:
  - {name: floor, shape: {type: plane, size: [3, 3]}, material: {type: diffuse, color: [0.7, 0.7, 0.7]}}
  - {name: box, shape: {type: box, size: [0.15, 0.15, 0.3]}, transform: {translation: [0.05, 0.05, 0.15]},
     material: {type: diffuse, color: [0.6, 0.5, 0.4]}}
views:
  - rig: procam
    look_at: [{eye: [0.1, -0.8, 0.9], target: [0.0, 0.0, 0.05]}]
"""


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    root = tmp_path_factory.mktemp("procam")
    spec = root / "procam.yaml"
    spec.write_text(PROCAM)
    out = root / "out"
    render_spec(spec, out, progress=False)
    d = Dataset(out)
    view = d.views[0]
    seq = d.pattern_sequence(view)
    return d, view, seq, d.projector_truth(view)


def projector_of(seq) -> tuple[Camera, Rigid3]:
    p = seq["projector"]
    return Camera.from_dict(p["camera"]), Rigid3.from_matrix(np.array(p["projector_from_world"]))


def test_the_run_verifies_and_holds_the_sequence(rendered):
    d, view, seq, t = rendered
    assert verify(d.root).ok
    assert [e["name"] for e in seq["patterns"]][:4] == ["white", "black", "u_bit05", "u_bit05_inv"]
    assert d.pattern_images(view).shape == (14, 36, 48, 3)
    assert np.array_equal(d.pattern_images(view)[0], d.image(view))  # the view's image is pattern 0's
    assert 0.3 < t.lit.mean() < 1.0  # the box casts a projector shadow


def test_projector_pixels_equal_opencv_projection_with_distortion_and_skew(rendered):
    d, view, seq, t = rendered
    proj, proj_from_world = projector_of(seq)
    P = d.points_world(view).astype(np.float64)  # the stored float32 truth points, taken exactly
    ok = np.isfinite(P).all(axis=-1)
    assert np.array_equal(ok, np.isfinite(t.uv).all(axis=-1))
    rvec, _ = cv2.Rodrigues(proj_from_world.R)
    # OpenCV's distortion with an identity K gives the distorted normalised point; OpenCV ignores
    # skew in projectPoints, so the affine K (skew in K[0, 1]) is applied here
    K, dist = proj.to_opencv()
    xd, _ = cv2.projectPoints(P[ok].reshape(-1, 1, 3), rvec, proj_from_world.t, np.eye(3), dist)
    xd = xd.reshape(-1, 2)
    uv = np.stack([K[0, 0] * xd[:, 0] + K[0, 1] * xd[:, 1] + K[0, 2], K[1, 1] * xd[:, 1] + K[1, 2]], axis=1)
    err = np.abs(uv - t.uv[ok])
    assert err.max() <= 1e-6, err.max()
    assert proj.skew == 1.5 and np.abs(uv[:, 0]).max() > 10  # the skew and the distortion were exercised


def test_projector_shadows_equal_a_trimesh_ray_cast(rendered):
    d, view, seq, t = rendered
    proj, proj_from_world = projector_of(seq)
    mesh = trimesh.util.concatenate([d.mesh(n) for n in d.mesh_names])
    P = d.points_world(view).astype(np.float64).reshape(-1, 3)
    N = d.truth(view)["normals_world"].astype(np.float64).reshape(-1, 3)
    _, cam_from_world = d.camera(view)
    C_cam, C_proj = cam_from_world.inverse().t, proj_from_world.inverse().t
    ok = np.isfinite(P).all(axis=1)
    uv = t.uv.reshape(-1, 2)
    col, row = np.floor(uv[:, 0] + 0.5), np.floor(uv[:, 1] + 0.5)
    inside = ok & (col >= 0) & (col < proj.width) & (row >= 0) & (row < proj.height)
    facing = np.sign(np.einsum("ij,ij->i", N, C_cam - P)) * np.einsum("ij,ij->i", N, C_proj - P) > 0
    cand = np.flatnonzero(inside & facing)
    dirs = P[cand] - C_proj
    dist = np.linalg.norm(dirs, axis=1)
    locs, ray_idx, _ = trimesh.ray.ray_triangle.RayMeshIntersector(mesh).intersects_location(
        np.broadcast_to(C_proj, dirs.shape), dirs / dist[:, None], multiple_hits=True)
    first = np.full(len(cand), np.inf)
    np.minimum.at(first, ray_idx, np.linalg.norm(locs - C_proj, axis=1))
    expected = np.zeros(len(P), bool)
    expected[cand] = first >= dist * (1 - 1e-4)  # nothing before the point (its own surface aside)
    lit = t.lit.ravel()
    assert expected.sum() > 200 and (inside & facing & ~expected).sum() > 50  # lit pixels and shadowed ones
    assert np.array_equal(lit, expected), np.flatnonzero(lit != expected)


def test_a_gray_code_decode_of_the_patterns_reads_the_truth_codes(rendered):
    d, view, seq, t = rendered
    imgs = d.pattern_images(view).astype(np.float64).mean(axis=-1)
    bits = [(e["bit"], imgs[e["index"]], imgs[e["index"] + 1]) for e in seq["patterns"]
            if e["axis"] == "columns" and not e["inverse"]]
    gray = sum(((pos > neg).astype(np.int64) << b) for b, pos, neg in bits)
    # a camera pixel whose footprint straddles a projector column edge (or a shadow or depth edge)
    # sees two codes and may read either; where its four corners see lit points of its own column
    # (clear_column) the decode reads exactly that column's Gray code
    clear = t.clear_column
    assert clear.sum() > 200 and (clear <= t.lit).all() and (t.lit & ~clear).sum() > 50
    assert np.array_equal(gray[clear], t.gray_column[clear]), np.flatnonzero(gray[clear] != t.gray_column[clear])
    # clear pixels lie away from their column's edges by at least the footprint's reach there
    u = t.uv[..., 0]
    frac = u + 0.5 - np.floor(u + 0.5)
    assert np.nanmin(np.minimum(frac, 1 - frac)[clear]) > 0.01
    assert np.array_equal(t.gray_column[t.lit], t.column[t.lit] ^ (t.column[t.lit] >> 1))
    assert (t.column[~t.lit] == -1).all() and (t.gray_row[~t.lit] == -1).all() and not t.clear_row[~t.lit].any()
