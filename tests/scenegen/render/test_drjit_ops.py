"""The camera arithmetic on Dr.Jit float32 arrays (the renderer's rays) matches numpy."""
import numpy as np
import pytest

from scenegen.geometry.camera import Camera, project_xyz, unproject_uv
from scenegen.geometry.conventions import pixel_centers
from scenegen.render import load_mitsuba

pytestmark = pytest.mark.render

# float32 floor of the camera arithmetic, measured 4.0e-5 px (opencv, k1 = -0.4, k3 = -0.05)
# over a full 640x480 grid (tests/scenegen/geometry/test_camera.py).
TOL_FLOAT32_PX = 1.5e-4


def test_same_code_on_drjit_arrays():
    """unproject_uv / project_xyz with Dr.Jit's ops give Dr.Jit arrays that match numpy's."""
    mi = load_mitsuba("llvm_ad_rgb")
    import drjit as dr  # once the variant is set

    from scenegen.render.drjit_ops import DRJIT_OPS

    cam = Camera.from_opencv(np.array([[800.0, 0, 319.5], [0, 800.0, 239.5], [0, 0, 1]]),
                             [-0.4, 0.0, 0.0, 0.0, -0.05], (640, 480))
    grid = pixel_centers(cam.width, cam.height).reshape(-1, 2)[::11].astype(np.float32)
    p = cam.params()
    d_dr = unproject_uv(mi.Float(grid[:, 0]), mi.Float(grid[:, 1]), p, cam.model, cam.undistort_iterations,
                        DRJIT_OPS)
    assert all(type(c).__module__.startswith("drjit") for c in d_dr)
    d_np = unproject_uv(grid[:, 0], grid[:, 1], p, cam.model, cam.undistort_iterations)
    for a, b in zip(d_dr, d_np):
        np.testing.assert_allclose(np.asarray(a), b, rtol=0, atol=2e-6)
    u, v, valid = project_xyz(*(mi.Float(c) for c in d_np), p, cam.model, DRJIT_OPS)
    assert bool(dr.all(valid))
    np.testing.assert_allclose(np.asarray(u), grid[:, 0], rtol=0, atol=TOL_FLOAT32_PX)
    np.testing.assert_allclose(np.asarray(v), grid[:, 1], rtol=0, atol=TOL_FLOAT32_PX)
