import itertools

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.triangulation import (
    noisy_observations,
    projection_matrix,
    score_triangulation,
    triangulate_opencv,
    triangulation_angle_deg,
)
from scenegen.geometry.camera import Camera

# cv2.triangulatePoints solves the unnormalised 4x4 DLT in float64: pixel coordinates ~1e2-1e3 and
# metres ~1 condition it to ~1e4, so noise-free points come back to ~1e-12 relative; 1e-9 relative
# to depth is the "float precision" with that margin.
NOISE_FREE_REL_TOL = 1e-9

CAM = Camera("pinhole", 640, 480, 600.0, 600.0, 319.5, 239.5)
TARGET = np.array([0.0, 0.0, 0.0])


@pytest.fixture
def convergent_pair(look_at_cam_from_world):
    """``convergent_pair(angle_deg, distance=5)``: two cameras at ``distance`` from TARGET, seeing
    it under ``angle_deg`` between them."""
    def make(angle_deg, distance=5.0):
        a = np.radians(angle_deg) / 2
        c1 = distance * np.array([np.sin(-a), -np.cos(a), 0.3])
        c2 = distance * np.array([np.sin(a), -np.cos(a), 0.3])
        return look_at_cam_from_world(c1, TARGET), look_at_cam_from_world(c2, TARGET)
    return make


def observe(pose, X):
    R, t = pose
    return CAM.project(X @ R.T + t)


def points(n=2000, seed=0):
    return np.random.default_rng(seed).uniform(-0.5, 0.5, size=(n, 3))


@pytest.fixture
def run(convergent_pair):
    """``run(angle_deg, sigma, seed=0)``: OpenCV's triangulation of a convergent pair, scored."""
    def make(angle_deg, sigma, seed=0):
        p1, p2 = convergent_pair(angle_deg)
        X = points(seed=seed)
        x1 = noisy_observations(observe(p1, X), sigma, seed=seed + 1)
        x2 = noisy_observations(observe(p2, X), sigma, seed=seed + 2)
        Xe = triangulate_opencv(projection_matrix(CAM.K, *p1), projection_matrix(CAM.K, *p2), x1, x2)
        return score_triangulation(Xe, X, p1, p2)
    return make


@pytest.mark.parametrize("angle", [1.0, 10.0, 60.0])
def test_noise_free_recovers_truth(angle, run):
    s = run(angle, 0.0)
    assert s.n_failed == 0
    assert np.max(s.rel_err) < NOISE_FREE_REL_TOL, np.max(s.rel_err)


def test_error_grows_as_baseline_angle_shrinks(run):
    angles = [40.0, 20.0, 10.0, 5.0, 2.0, 1.0]
    med = [run(a, 1.0).median_m for a in angles]
    assert all(b > a for a, b in itertools.pairwise(med)), med
    # First-order theory: depth error ~ sigma z / (f sin(angle)): ~40x from 40 to 1 degree.
    assert med[-1] / med[0] > 10


def test_binned_error_grows_as_angle_shrinks_in_one_scene(look_at_cam_from_world):
    # A 0.5 m stereo pair and points from 1 m to 40 m in front: angles ~28 down to ~0.7 degrees.
    c1, c2 = np.array([-0.25, 0.0, 0.0]), np.array([0.25, 0.0, 0.0])
    p1 = look_at_cam_from_world(c1, c1 + [0.0, 1.0, 0.0])
    p2 = look_at_cam_from_world(c2, c2 + [0.0, 1.0, 0.0])
    rng = np.random.default_rng(3)
    depth = rng.uniform(1.0, 40.0, 5000)
    X = np.stack([rng.uniform(-0.1, 0.1, 5000) * depth, depth, rng.uniform(-0.1, 0.1, 5000) * depth], axis=1)
    x1 = noisy_observations(observe(p1, X), 1.0, seed=4)
    x2 = noisy_observations(observe(p2, X), 1.0, seed=5)
    s = score_triangulation(triangulate_opencv(projection_matrix(CAM.K, *p1), projection_matrix(CAM.K, *p2), x1, x2),
                            X, p1, p2)
    np.testing.assert_array_equal([b.n for b in s.bins], np.histogram(s.angle_deg, [b.lo_deg for b in s.bins]
                                                                      + [s.bins[-1].hi_deg])[0])
    used = [b for b in s.bins if b.n >= 100]
    assert len(used) >= 4
    med = [b.median_m for b in used]  # increasing angle
    assert all(b < a for a, b in itertools.pairwise(med)), med


def test_angle_is_exact_for_known_geometry(convergent_pair):
    p1, p2 = convergent_pair(30.0)
    c1, c2 = -p1[0].T @ p1[1], -p2[0].T @ p2[1]
    # at the target the two rays are 30 degrees apart in the horizontal plane, lifted by z = 0.3 d
    u, v = c1 - TARGET, c2 - TARGET
    expect = np.degrees(np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v)))
    assert triangulation_angle_deg(TARGET[None], c1, c2)[0] == pytest.approx(expect, abs=1e-12)


def test_known_offset_and_failures(convergent_pair):
    p1, p2 = convergent_pair(10.0)
    X = points(10)
    Xe = X + np.array([0.0, 0.0, 0.01])
    Xe[3] = np.nan
    s = score_triangulation(Xe, X, p1, p2)
    assert s.n_failed == 1 and s.err_m[3] == np.inf and s.mean_m == np.inf and s.rms_m == np.inf
    np.testing.assert_allclose(np.delete(s.err_m, 3), 0.01, rtol=1e-12)
    z = X @ p1[0][2] + p1[1][2]
    np.testing.assert_allclose(np.delete(s.rel_err, 3), np.delete(0.01 / z, 3), rtol=1e-12)
    assert sum(b.n for b in s.bins) == 10 and sum(b.n_failed for b in s.bins) == 1


def test_bad_input(convergent_pair):
    p1, p2 = convergent_pair(10.0)
    with pytest.raises(InputError):
        score_triangulation(np.zeros((3, 3)), np.zeros((4, 3)), p1, p2)
    behind = np.array([[0.0, -20.0, 0.0]])  # behind camera 1
    with pytest.raises(InputError):
        score_triangulation(behind, behind, p1, p2)
    with pytest.raises(InputError):
        noisy_observations(np.zeros((2, 2)), -1.0)
