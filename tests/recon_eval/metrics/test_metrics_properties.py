"""Property tests (hypothesis): planted transforms and angles over random draws."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from recon_eval.metrics.align import Sim3, umeyama
from scenegen.geometry.rotation import rotation_angle_rad

finite = st.floats(-10.0, 10.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(rotvec=st.tuples(finite, finite, finite), t=st.tuples(finite, finite, finite),
       log_scale=st.floats(-3.0, 3.0), seed=st.integers(0, 2**31 - 1))
def test_umeyama_recovers_any_planted_sim3(rotvec, t, log_scale, seed):
    T = Sim3(Rotation.from_rotvec(rotvec).as_matrix(), t, float(np.exp(log_scale)))
    src = np.random.default_rng(seed).normal(size=(12, 3))
    est = umeyama(src, T.apply(src), with_scale=True)
    # relative to the transform's magnitude: |t| up to 17 m, scale up to e^3
    np.testing.assert_allclose(est.matrix, T.matrix, atol=1e-9 * max(1.0, np.abs(T.matrix).max()))


@settings(max_examples=200, deadline=None)
@given(axis=st.tuples(finite, finite, finite).filter(lambda a: np.linalg.norm(a) > 1e-3),
       angle=st.floats(0.0, np.pi - 1e-6))
def test_rotation_angle_of_any_axis_angle(axis, angle):
    axis = np.asarray(axis) / np.linalg.norm(axis)
    R = Rotation.from_rotvec(angle * axis).as_matrix()
    assert abs(rotation_angle_rad(R) - angle) <= 1e-14 + 1e-12 * angle
