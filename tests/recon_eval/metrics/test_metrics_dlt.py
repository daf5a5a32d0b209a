import cv2
import numpy as np
import pytest

from recon_eval.metrics.dlt import (
    decompose_projection,
    dlt_projection,
    project_with_P,
    score_projection,
    score_projection_projective,
)
from recon_eval.errors import InputError
from scenegen.geometry.camera import Camera

# RQ of an exactly built P is backward stable: float64 rounding (1e-16) times the condition of
# K (fx / 1 ~ 1e3) and of the scale leaves ~1e-13; 1e-9 relative is the requirement.
REL_TOL = 1e-9
# OpenCV's decomposeProjectionMatrix works in float64 by Givens rotations: agreement to rounding,
# with the same 1e-9 relative margin.
CV_TOL = 1e-9
# Noise-free DLT from 50 points recovers P to ~1e-12 relative; the scores built on it (pixels,
# degrees, metres) are then below 1e-7 with a 10^3 margin for the conditioning of the 12x12 SVD.
DLT_TOL = 1e-7


@pytest.fixture
def random_camera(random_rotation):
    """``random_camera(rng)``: (K, R, t) of a random pinhole camera with skew."""
    def make(rng):
        fx = rng.uniform(300, 1500)
        K = np.array([[fx, rng.uniform(-5, 5), rng.uniform(200, 800)],
                      [0.0, fx * rng.uniform(0.8, 1.25), rng.uniform(150, 600)],
                      [0.0, 0.0, 1.0]])
        return K, random_rotation(rng), rng.normal(size=3) * 3
    return make


def rel_err(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(b)))


def test_rq_recovers_K_R_t_on_random_cameras(random_camera):
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(200):
        K, R, t = random_camera(rng)
        P = rng.uniform(1e-3, 1e3) * K @ np.hstack([R, t[:, None]])
        Ke, Re, te = decompose_projection(P)
        worst = max(worst, rel_err(Ke, K), rel_err(Re, R), rel_err(te, t))
        assert np.linalg.det(Re) == pytest.approx(1.0, abs=REL_TOL)
        assert Ke[2, 2] == 1.0 and np.all(np.diag(Ke) > 0)
        assert Ke[1, 0] == Ke[2, 0] == Ke[2, 1] == 0.0
    assert worst < REL_TOL, worst


def test_negative_scale_is_handled(random_camera):
    rng = np.random.default_rng(2)
    for _ in range(50):
        K, R, t = random_camera(rng)
        P = -rng.uniform(1e-3, 1e3) * K @ np.hstack([R, t[:, None]])
        Ke, Re, te = decompose_projection(P)
        assert rel_err(Ke, K) < REL_TOL and rel_err(Re, R) < REL_TOL and rel_err(te, t) < REL_TOL


def test_opencv_decompose_projection_matrix_agrees(random_camera):
    rng = np.random.default_rng(3)
    for _ in range(50):
        K, R, t = random_camera(rng)
        P = rng.uniform(0.1, 10) * K @ np.hstack([R, t[:, None]])
        Ke, Re, te = decompose_projection(P)
        Kc, Rc, Ch = cv2.decomposeProjectionMatrix(P)[:3]
        Kc = Kc / Kc[2, 2]
        C = Ch[:3, 0] / Ch[3, 0]
        assert rel_err(Ke, Kc) < CV_TOL
        assert rel_err(Re, Rc) < CV_TOL
        assert rel_err(-Re.T @ te, C) < CV_TOL


def test_singular_and_malformed_P_raise():
    with pytest.raises(InputError):
        decompose_projection(np.hstack([np.ones((3, 3)), np.ones((3, 1))]))
    with pytest.raises(InputError):
        decompose_projection(np.zeros((3, 3)))
    with pytest.raises(InputError):
        decompose_projection(np.full((3, 4), np.nan))


@pytest.fixture
def one_view(look_at_cam_from_world):
    """``one_view(rng, n=50)``: (camera, R, t, points (n, 3), their pixels) of one pinhole view."""
    def make(rng, n=50):
        cam = Camera("pinhole", 640, 480, 610.0, 590.0, 321.5, 238.25, 1.5)
        R, t = look_at_cam_from_world([4.0, -3.0, 2.0], target=[0.1, 0.2, 0.0])
        X = rng.uniform(-1, 1, size=(n, 3))
        px = cam.project(X @ R.T + t)
        return cam, R, t, X, px
    return make


def test_dlt_estimate_scores_zero_and_projection_matches_camera(one_view):
    rng = np.random.default_rng(4)
    cam, R, t, X, px = one_view(rng)
    P_true = cam.K @ np.hstack([R, t[:, None]])
    np.testing.assert_allclose(project_with_P(P_true, X), px, atol=1e-9)  # same pinhole model
    P = dlt_projection(X, px)
    s = score_projection(-3.0 * P, cam.K, (R, t), X, px)  # any scale, either sign
    assert not s.failed and s.n_points == 50 and s.n_invalid == 0
    for f in ("fx_abs_err_px", "fy_abs_err_px", "cx_abs_err_px", "cy_abs_err_px", "skew_abs_err_px",
              "rot_err_deg", "trans_abs_err_m", "center_err_m", "reproj_rms_px", "reproj_max_px"):
        assert getattr(s, f) < DLT_TOL, (f, getattr(s, f))


def test_score_projection_known_errors(one_view):
    rng = np.random.default_rng(5)
    cam, R, t, X, px = one_view(rng)
    K2 = cam.K.copy()
    K2[0, 0] += 6.1  # fx off by 1 %
    R2 = np.array([[np.cos(0.01), -np.sin(0.01), 0], [np.sin(0.01), np.cos(0.01), 0], [0, 0, 1]]) @ R
    s = score_projection(K2 @ np.hstack([R2, t[:, None]]), cam.K, (R, t), X, px)
    assert s.fx_abs_err_px == pytest.approx(6.1, abs=1e-9)
    assert s.fx_rel_err == pytest.approx(0.01, abs=1e-12)
    assert s.rot_err_deg == pytest.approx(np.degrees(0.01), abs=1e-9)
    assert s.trans_abs_err_m == pytest.approx(0.0, abs=1e-12)
    assert s.center_err_m > 0 and s.reproj_rms_px > 1.0


def test_failed_estimate_is_inf_not_exception(one_view):
    rng = np.random.default_rng(6)
    cam, R, t, X, px = one_view(rng)
    s = score_projection(np.full((3, 4), np.nan), cam.K, (R, t), X, px)
    assert s.failed and s.rot_err_deg == np.inf and s.reproj_rms_px == np.inf and s.n_invalid == 50


def test_projective_frame_scored_after_15dof_alignment(one_view):
    rng = np.random.default_rng(7)
    cam, R, t, X, px = one_view(rng, n=60)
    H = np.eye(4) + 0.3 * rng.normal(size=(4, 4))  # truth_from_proj, a generic projective map
    Xh = np.hstack([X, np.ones((len(X), 1))]) @ np.linalg.inv(H).T
    X_proj = Xh[:, :3] / Xh[:, 3:4]
    P_proj = dlt_projection(X_proj, px)  # camera estimated in the projective frame
    # Without alignment the decomposition is meaningless ...
    raw = score_projection(P_proj, cam.K, (R, t))
    assert raw.rot_err_deg > 1.0 or raw.fx_rel_err > 0.1
    # ... after the 15-DoF alignment on the points, K, R, t and reprojection are exact.
    s = score_projection_projective(P_proj, X_proj, X, cam.K, (R, t), px)
    for f in ("fx_rel_err", "fy_rel_err", "cx_rel_err", "cy_rel_err", "skew_abs_err_px", "rot_err_deg",
              "trans_abs_err_m", "reproj_rms_px"):
        assert getattr(s, f) < DLT_TOL, (f, getattr(s, f))
