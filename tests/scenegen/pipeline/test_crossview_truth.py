"""Cross-view truth against geometry and independent implementations (issue 5, "What it must
show"): ray casts from view j, the i -> j -> i cycle, epipolar geometry (ours vs
cv2.findFundamentalMat), plane homographies, and occlusion masks vs an analytic occluder."""
import cv2
import numpy as np
import pytest

from scenegen.crossview.correspondence import correspond
from scenegen.dataset import Dataset
from scenegen.dataset.crossview import NO_SURFACE, OCCLUDED, OCCLUSION_REL_TOL, OUT_OF_FRAME, VISIBLE
from scenegen.geometry.conventions import in_image
from scenegen.geometry.twoview import TwoView, sampson_error, undistorted_pixels
from scenegen.render import load_mitsuba, load_scene
from scenegen.spec import parse_spec, resolve_views

pytestmark = pytest.mark.render

# A ray cast from j through the stored correspondence hits pixel i's truth point within this
# fraction of its depth: the bound (float32 intersection and storage: ~1e-6 measured).
TOL_SAME_POINT_REL = 1e-4
# i -> j -> i cycle, pixels: the bound (float32 ray casts: ~1e-4 px measured).
TOL_CYCLE_PX = 1e-3
# The cycle's second leg is a float32 ray cast from j: its direction is rounded to ~6e-8 rad and
# the stored (float32) position to ~8e-6 px, and where j sees the surface at grazing incidence
# theta both errors slide the hit along the surface by a factor 1 / cos(theta) (measured: 1.0e-3 px
# at cos = 0.0027 on the sphere's limb). Below cos = 0.02 (88.9 degrees) the check measures the
# float32 instrument, not the truth, so those pixels are excluded from the cycle bound, counted,
# and required to be rare (< 1 % of the visible pixels).
GRAZING_MIN_COS = 0.02
MAX_GRAZING_FRACTION = 0.01
# Sampson error on truth correspondences, px^2: the bound.
TOL_SAMPSON_PX2 = 1e-6
# Our F vs cv2.findFundamentalMat (8-point, all truth correspondences), after normalising both
# to unit Frobenius norm and sign: the inputs are float32-stored positions (~1e-5 px), so the
# linear fit reproduces F to ~1e-7; 1e-5 leaves margin and still catches any convention slip.
TOL_F_VS_CV2 = 1e-5
# Plane homographies on truth correspondences of planar objects, px (float32 storage ~1e-5 px,
# float32 mesh vertices ~1e-7 m).
TOL_HOMOGRAPHY_PX = 1e-3
# Occlusion mask vs the analytic occluder: the bound.
MIN_OCCLUSION_IOU = 0.99


@pytest.fixture(scope="module")
def data(crossview_render, crossview_scene):
    spec, built = crossview_scene
    return Dataset(crossview_render[1]), built, spec


def pairs(ds):
    out = []
    for i, j in ds.crossview.pairs:
        out += [(i, j), (j, i)]
    return out


def load_corr(ds, i, j):
    return ds.crossview.correspondence(i, j)


def test_index_lists_pairs_and_states(data):
    ds, _, _ = data
    assert len(pairs(ds)) == 6
    for i, j in pairs(ds):
        c = load_corr(ds, i, j)
        counts = np.bincount(c.state.ravel(), minlength=4)
        assert counts[VISIBLE] > 1000, (i, j, counts)
        valid_i = ds.truth(i)["valid"]
        assert np.array_equal(c.state != NO_SURFACE, valid_i)
        # out-of-frame positions lie outside j's image, visible/occluded ones inside
        cam_j, _ = ds.camera(j)
        inside = in_image(c.uv.reshape(-1, 2), cam_j.width, cam_j.height).reshape(c.state.shape)
        assert not inside[c.state == OUT_OF_FRAME].any()
        assert inside[(c.state == VISIBLE) | (c.state == OCCLUDED)].all()
    # the sphere occludes part of the wall in the stereo pair
    c = load_corr(ds, "st_left_0000", "st_right_0000")
    assert (c.state == OCCLUDED).sum() > 20


def test_ray_from_j_hits_same_point_and_cycle(data):
    ds, built, _ = data
    worst_rel, worst_cycle, grazing, total = 0.0, 0.0, 0, 0
    for i, j in pairs(ds):
        c = load_corr(ds, i, j)
        t = ds.truth(i)
        cam_i, pose_i = ds.camera(i)
        cam_j, pose_j = ds.camera(j)
        vis = c.visible
        hit = built.surface_points(cam_j, pose_j, c.uv[vis])
        P = t["points_world"][vis].astype(np.float64)
        rel = np.linalg.norm(hit - P, axis=1) / t["depth_z"][vis]
        worst_rel = max(worst_rel, float(np.max(rel)))
        back = cam_i.project(pose_i.apply(hit))
        grid = np.stack(np.nonzero(vis)[::-1], 1).astype(float)
        ray_j = P - pose_j.inverse().t
        cos_j = np.abs(np.einsum("ij,ij->i", t["normals_world"][vis], ray_j)) / np.linalg.norm(ray_j, axis=1)
        ok = cos_j >= GRAZING_MIN_COS
        grazing += int((~ok).sum())
        total += int(vis.sum())
        worst_cycle = max(worst_cycle, float(np.max(np.abs(back - grid)[ok])))
    print(f"ray cast from j: max |hit - P| / depth = {worst_rel:.2e}; cycle i->j->i max {worst_cycle:.2e} px "
          f"({grazing} of {total} visible px at grazing incidence excluded from the cycle)")
    assert worst_rel < TOL_SAME_POINT_REL
    assert worst_cycle < TOL_CYCLE_PX
    assert grazing < MAX_GRAZING_FRACTION * total


def test_epipolar_geometry_sampson_and_cv2(data):
    ds, _, _ = data
    worst = 0.0
    for i, j in pairs(ds):
        c = load_corr(ds, i, j)
        cam_i, pose_i = ds.camera(i)
        cam_j, pose_j = ds.camera(j)
        if (i, j) in ds.crossview.pairs:
            F = ds.crossview.twoview(i, j).F
        else:  # the reverse direction: F_ji = F_ij^T
            F = ds.crossview.twoview(j, i).F.T
        vis = c.visible
        xi = undistorted_pixels(cam_i, np.stack(np.nonzero(vis)[::-1], 1).astype(float))
        xj = undistorted_pixels(cam_j, c.uv[vis])
        s = sampson_error(F, xi, xj)
        worst = max(worst, float(s.max()))
        F_cv, _ = cv2.findFundamentalMat(xi, xj, cv2.FM_8POINT)
        F_cv = F_cv / np.linalg.norm(F_cv)
        F_cv *= np.sign(np.sum(F_cv * F))
        assert np.abs(F_cv - F).max() < TOL_F_VS_CV2, (i, j, np.abs(F_cv - F).max())
        # epipoles are F's null vectors
        tv = TwoView.of(cam_i, pose_i, cam_j, pose_j)
        assert np.linalg.norm(tv.F @ tv.epipole_i) < 1e-9 and np.linalg.norm(tv.F.T @ tv.epipole_j) < 1e-9
    print(f"max Sampson error on truth correspondences: {worst:.2e} px^2")
    assert worst < TOL_SAMPSON_PX2


def test_plane_homographies(data):
    ds, _, spec = data
    p = ds.crossview.twoview("st_left_0000", "side_0002")
    assert set(p.homographies) == {"wall", "floor", "board"}
    c = load_corr(ds, "st_left_0000", "side_0002")
    t = ds.truth("st_left_0000")
    cam_i, _ = ds.camera("st_left_0000")
    cam_j, _ = ds.camera("side_0002")
    ids = {o.name: o.object_id for o in spec.objects}
    for name, H in p.homographies.items():
        m = c.visible & (t["object_id"] == ids[name])
        assert m.sum() > 50, name
        xi = undistorted_pixels(cam_i, np.stack(np.nonzero(m)[::-1], 1).astype(float))
        xj = undistorted_pixels(cam_j, c.uv[m])
        Hx = np.c_[xi, np.ones(len(xi))] @ H.T
        err = np.abs(Hx[:, :2] / Hx[:, 2:] - xj).max()
        assert err < TOL_HOMOGRAPHY_PX, (name, err)


OCC_SPEC = """
objects:
  - name: wall
    shape: {type: plane, size: [8, 8]}
    transform: {translation: [0, 3, 0], rotation_deg: [90, 0, 0]}
  - name: ball
    shape: {type: sphere, radius: 0.3}
    transform: {translation: [0.1, 1.2, 0.05]}
cameras:
  cam: {size: [240, 180], fov_deg: 60}
views:
  - camera: cam
    look_at: [{eye: [-0.3, -1.0, 0.0], target: [0, 3, 0]}, {eye: [0.45, -1.0, 0.1], target: [0.1, 3, 0]}]
"""


def _segment_hits_sphere(P, C, centre, r):
    """(N,) bool: the open segment P -> C passes within r of centre (analytic)."""
    d = C - P  # (N, 3)
    f = P - centre
    a = np.einsum("ij,ij->i", d, d)
    b = 2 * np.einsum("ij,ij->i", f, d)
    c = np.einsum("ij,ij->i", f, f) - r * r
    disc = b * b - 4 * a * c
    sq = np.sqrt(np.maximum(disc, 0))
    t1, t2 = (-b - sq) / (2 * a), (-b + sq) / (2 * a)
    return (disc > 0) & (((t1 > 1e-9) & (t1 < 1)) | ((t2 > 1e-9) & (t2 < 1)))


def test_occlusion_matches_analytic_sphere(tmp_path):
    spec = parse_spec(OCC_SPEC, base_dir=tmp_path)
    built = load_scene(spec, variant="llvm_ad_rgb", spp=1)
    vi, vj = resolve_views(spec)
    cam = built.cameras["cam"]
    t = built.truth(cam, vi.cam_from_world)
    P = np.where(t["valid"][..., None], t["points_world"], np.nan)
    corr = correspond(P, cam, vj.cam_from_world, built.visible_from)
    Cj = vj.cam_from_world.inverse().t
    centre, r = np.array([0.1, 1.2, 0.05]), 0.3
    flat = P.reshape(-1, 3)
    inside = np.isin(corr.state.ravel(), (VISIBLE, OCCLUDED))
    on_wall = (t["object_id"].ravel() == 1)
    on_ball = (t["object_id"].ravel() == 2)
    analytic = np.zeros(len(flat), bool)
    analytic[on_wall] = _segment_hits_sphere(flat[on_wall], Cj[None], centre, r)
    n = (flat[on_ball] - centre) / r
    analytic[on_ball] = np.einsum("ij,ij->i", Cj[None] - flat[on_ball], n) <= 0  # back-facing to j
    analytic &= inside
    ours = corr.state.ravel() == OCCLUDED
    iou = (ours & analytic).sum() / (ours | analytic).sum()
    print(f"occlusion IoU vs analytic sphere: {iou:.5f} ({analytic.sum()} occluded px)")
    assert analytic.sum() > 500
    assert iou > MIN_OCCLUSION_IOU


def test_occlusion_tolerance_is_relative_to_distance(tmp_path):
    """A point on a surface is visible; a point behind it by 10x the tolerance is occluded; the
    threshold scales with distance."""
    mi = load_mitsuba("llvm_ad_rgb")
    from scenegen.render.raycast import visible_from  # Mitsuba's, once the variant is set
    scene = mi.load_dict({"type": "scene", "wall": {"type": "rectangle", "to_world":
                          mi.ScalarTransform4f().translate([0, 0, 5.0]).scale(10)}})
    C = np.zeros(3)
    for dist in (5.0,):
        on = np.array([[0.3, -0.2, dist]])
        direction = on / np.linalg.norm(on)
        D = np.linalg.norm(on)
        behind_far = direction * D * (1 + 10 * OCCLUSION_REL_TOL)
        behind_near = direction * D * (1 + 0.1 * OCCLUSION_REL_TOL)
        front = direction * D * (1 - 10 * OCCLUSION_REL_TOL)
        v = visible_from(scene, C, np.vstack([on, behind_near, behind_far, front]))
        assert v.tolist() == [True, True, False, True]
