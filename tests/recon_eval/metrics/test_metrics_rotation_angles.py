import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from scenegen.geometry.rotation import (
    angle_between_vectors_rad,
    is_rotation,
    rotation_angle_rad,
    rotation_error_rad,
    matrix_from_rotvec,
)


class TestRotationAngle:
    @pytest.mark.parametrize("theta", [0.0, 1e-12, 1e-8, 1e-4, 0.3, 1.0, 2.5, np.pi - 1e-6])
    def test_known_angle(self, theta):
        axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
        R = matrix_from_rotvec(theta * axis)
        # Rounding of R's entries (~1e-16) bounds the absolute error; relative for small angles.
        assert rotation_angle_rad(R) == pytest.approx(theta, rel=1e-9, abs=1e-15)

    def test_precise_near_zero_where_arccos_fails(self):
        theta = 1e-8
        R = matrix_from_rotvec([0.0, 0.0, theta])
        got = rotation_angle_rad(R)
        assert got == pytest.approx(theta, rel=1e-9)
        arccos_form = np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))
        assert abs(arccos_form - theta) / theta > 0.1  # the form the note warns against

    def test_matches_opencv_rodrigues_and_scipy(self):
        Rs = Rotation.random(50, random_state=4).as_matrix()
        ours = rotation_angle_rad(Rs)
        scipy_mag = Rotation.from_matrix(Rs).magnitude()
        cv_mag = np.array([np.linalg.norm(cv2.Rodrigues(R)[0]) for R in Rs])
        np.testing.assert_allclose(ours, scipy_mag, atol=1e-12)
        np.testing.assert_allclose(ours, cv_mag, atol=1e-9)  # cv2.Rodrigues: SVD projection + acos, ~1e-9 near 0

    def test_rotation_error_is_symmetric(self):
        A = Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix()
        B = Rotation.from_rotvec([-0.3, 0.1, 0.0]).as_matrix()
        assert rotation_error_rad(A, B) == pytest.approx(rotation_error_rad(B, A), abs=1e-15)
        assert rotation_error_rad(A, B) == pytest.approx(Rotation.from_matrix(A.T @ B).magnitude(), abs=1e-12)

    def test_non_finite_gives_nan(self):
        assert np.isnan(rotation_angle_rad(np.full((3, 3), np.nan)))

    def test_batch_shape(self):
        assert rotation_angle_rad(np.tile(np.eye(3), (4, 2, 1, 1))).shape == (4, 2)


class TestAngleBetweenVectors:
    def test_known(self):
        assert angle_between_vectors_rad([1, 0, 0], [0, 2, 0]) == pytest.approx(np.pi / 2)
        assert angle_between_vectors_rad([1, 0, 0], [-3, 0, 0]) == pytest.approx(np.pi)
        assert angle_between_vectors_rad([1, 0, 0], [1, 1e-9, 0]) == pytest.approx(1e-9, rel=1e-9)

    def test_zero_vector_is_nan(self):
        assert np.isnan(angle_between_vectors_rad([0, 0, 0], [1, 0, 0]))


def test_is_rotation():
    assert is_rotation(np.eye(3))
    assert not is_rotation(np.diag([1.0, 1.0, -1.0]))
    assert not is_rotation(2 * np.eye(3))
