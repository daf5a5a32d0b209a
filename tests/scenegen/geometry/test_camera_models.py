"""Every model of the camera-model registry, round-tripped over its full pixel grid and at many
depths, in float64 and in the renderer's float32, and through its dict, OpenCV and COLMAP forms.

Adding a model to ``scenegen.geometry.camera.MODELS`` without an example camera here fails
:func:`test_every_registered_model_has_an_example`.
"""
import numpy as np
import pytest
from test_camera import TOL_FLOAT32_PX, TOL_ROUNDTRIP_PX, strong_opencv, wide_fisheye

from scenegen.geometry.camera import MODEL_NAMES, MODELS, Camera, camera_model, unproject_uv
from scenegen.geometry.conventions import pixel_centers

#: One demanding camera per model: strong distortion, skew where the model has it, 640 x 480.
EXAMPLES = {
    "pinhole": lambda: Camera("pinhole", 640, 480, 810.0, 800.0, 322.5, 236.0, skew=1.5),
    "opencv": strong_opencv,
    "fisheye": wide_fisheye,
}


def test_every_registered_model_has_an_example():
    assert set(EXAMPLES) == set(MODELS) and MODEL_NAMES == tuple(MODELS)


@pytest.fixture(params=MODEL_NAMES)
def camera(request) -> Camera:
    return EXAMPLES[request.param]()


def full_grid(cam: Camera) -> np.ndarray:
    return pixel_centers(cam.width, cam.height).reshape(-1, 2)


def test_full_pixel_grid(camera):
    grid = full_grid(camera)
    rays = camera.unproject_unit(grid)
    np.testing.assert_allclose(np.linalg.norm(rays, axis=1), 1.0, atol=1e-12)
    err = np.abs(camera.project(rays) - grid).max()
    assert err < TOL_ROUNDTRIP_PX, err


def test_unproject_of_projected_point_is_its_ray(camera):
    rng = np.random.default_rng(7)
    rays_true = camera.unproject_unit(rng.uniform([-0.5, -0.5], [camera.width - 0.5, camera.height - 0.5], (5000, 2)))
    X = rays_true * rng.uniform(0.5, 20.0, (5000, 1))  # many depths
    uv = camera.project(X)
    rays = camera.unproject_unit(uv)
    # angle between X and its recovered ray, expressed in pixels via the focal length
    ang = np.arctan2(np.linalg.norm(np.cross(rays, X), axis=1), np.sum(rays * X, axis=1))
    assert np.max(ang) * camera.fx < TOL_ROUNDTRIP_PX
    assert np.abs(camera.project(rays) - uv).max() < TOL_ROUNDTRIP_PX


def test_float32_floor(camera):
    """The same arithmetic in float32 (the renderer's rays) stays within the measured floor."""
    grid = full_grid(camera).astype(np.float32)
    d = unproject_uv(grid[:, 0], grid[:, 1], camera.params(), camera.model, camera.undistort_iterations)
    assert all(np.asarray(c).dtype == np.float32 for c in d)
    rays = np.stack(d, axis=1).astype(np.float64)
    err = np.abs(camera.project(rays) - grid).max()
    assert err < TOL_FLOAT32_PX, err


def test_dict_round_trip(camera):
    assert Camera.from_dict(camera.to_dict()) == camera


def test_opencv_round_trip(camera):
    K, d = camera.to_opencv()
    back = (Camera.from_opencv_fisheye(K, d, camera.size) if camera_model(camera.model).opencv_fisheye
            else Camera.from_opencv(K, d, camera.size))
    assert back == camera


def test_colmap_round_trip(camera):
    """COLMAP has no skew: compared on the camera without it."""
    plain = Camera(camera.model, camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy, 0.0,
                   camera.dist)
    name, params = plain.to_colmap()
    assert Camera.from_colmap(name, plain.width, plain.height, params) == plain


def test_registry_describes_the_dist_vector(camera):
    m = camera_model(camera.model)
    assert len(camera.dist) == len(m.coefficients) and list(camera.coefficients()) == list(m.coefficients)
    for n in m.dist_lengths:  # every accepted length builds the same model
        Camera(camera.model, 64, 48, 50.0, 50.0, 31.5, 23.5, 0.0, (0.0,) * n)
