"""Each foreign convention's one conversion, checked against the foreign software or geometry."""
import numpy as np
import pycolmap
import pytest
from scipy.spatial.transform import Rotation

from scenegen.geometry import conventions as cv
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3, camera_center, look_at


def random_pose(seed: int) -> Rigid3:
    rng = np.random.default_rng(seed)
    return Rigid3(Rotation.random(random_state=seed).as_matrix(), rng.normal(size=3))


@pytest.mark.parametrize("seed", range(5))
def test_rigid_algebra(seed):
    a, b = random_pose(seed), random_pose(seed + 100)
    x = np.random.default_rng(seed).normal(size=(10, 3))
    np.testing.assert_allclose((a @ b).apply(x), a.apply(b.apply(x)), atol=1e-12)
    assert (a @ a.inverse()).allclose(Rigid3.identity(), atol=1e-12)
    np.testing.assert_allclose(camera_center(a), -a.R.T @ a.t, atol=1e-12)


def test_look_at_axes():
    world_from_cam = look_at([2.0, 0.0, 0.0], [0.0, 0.0, 0.0], up=[0, 0, 1])
    cam_from_world = world_from_cam.inverse()
    np.testing.assert_allclose(cam_from_world.apply([[0.0, 0.0, 0.0]]), [[0, 0, 2.0]], atol=1e-12)
    # world up points to image up (-y); the camera's right (+x) is world -y when looking along -x
    np.testing.assert_allclose(cam_from_world.rotate([0, 0, 1.0]), [0, -1.0, 0], atol=1e-12)
    np.testing.assert_allclose(world_from_cam.rotate([1.0, 0, 0]), [0, 1.0, 0], atol=1e-12)


@pytest.mark.render
def test_mitsuba_to_world_matches_mitsuba_look_at():
    """Mitsuba's own look_at builds the same camera-to-world (x left, y up, z forward)."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    eye, target, up = [1.0, -2.0, 0.5], [0.2, 0.3, 0.1], [0.0, 0.0, 1.0]
    ours = cv.mitsuba_to_world(look_at(eye, target, up).inverse())
    theirs = np.array(mi.ScalarTransform4f().look_at(origin=eye, target=target, up=up).matrix)
    np.testing.assert_allclose(ours, theirs, atol=1e-6)
    back = cv.cam_from_world_from_mitsuba(ours)
    assert back.allclose(look_at(eye, target, up).inverse(), atol=1e-12)


def test_opengl_nerf_camera_to_world():
    """OpenGL camera: looks down its -z, +y is image up; position is the camera centre."""
    eye, target = np.array([0.5, 1.0, 2.0]), np.zeros(3)
    cam_from_world = look_at(eye, target).inverse()
    T = cv.opengl_cam_to_world(cam_from_world)
    forward = -T[:3, 2]
    np.testing.assert_allclose(forward, (target - eye) / np.linalg.norm(target - eye), atol=1e-12)
    np.testing.assert_allclose(T[:3, 3], eye, atol=1e-12)
    image_up_world = T[:3, 1]
    np.testing.assert_allclose(image_up_world, cam_from_world.inverse().rotate([0, -1.0, 0]), atol=1e-12)
    assert cv.cam_from_world_from_opengl(T).allclose(cam_from_world, atol=1e-12)
    # Blender shares the OpenGL camera axes in the same Z-up world
    np.testing.assert_array_equal(cv.blender_matrix_world(cam_from_world), T)


@pytest.mark.parametrize("seed", range(5))
def test_colmap_pose_against_pycolmap(seed):
    pose = random_pose(seed)
    q_wxyz, t = cv.colmap_pose(pose)
    rig = pycolmap.Rigid3d(rotation=pycolmap.Rotation3d(pose.R), translation=pose.t)
    q_xyzw = np.asarray(rig.rotation.quat)
    q_theirs = np.r_[q_xyzw[3], q_xyzw[:3]]
    q_theirs = q_theirs if q_theirs[0] >= 0 else -q_theirs
    np.testing.assert_allclose(q_wxyz, q_theirs, atol=1e-12)
    assert cv.cam_from_world_from_colmap(q_wxyz, t).allclose(pose, atol=1e-12)


def test_pixel_conventions():
    np.testing.assert_array_equal(cv.colmap_from_opencv_pixels([0.0, 0.0]), [0.5, 0.5])
    np.testing.assert_array_equal(cv.opencv_from_colmap_pixels([0.5, 0.5]), [0.0, 0.0])
    # Mitsuba film: the centre of pixel (i, j) is at film (i + 0.5) / W
    assert cv.opencv_pixel_from_film((0.5 / 640, 0.5 / 480), (640, 480)) == (0.0, 0.0)
    assert cv.film_from_opencv_pixel((639.0, 479.0), (640, 480)) == (1 - 0.5 / 640, 1 - 0.5 / 480)
    g = cv.pixel_centers(4, 3)
    assert g.shape == (3, 4, 2) and tuple(g[2, 3]) == (3.0, 2.0)


def test_depth_and_range():
    cam = Camera.from_fov(90.0, (64, 48))
    rays = cam.unproject(np.array([[0.0, 0.0], [31.5, 23.5]]))
    depth = np.array([2.0, 2.0])
    rng = cv.range_from_depth_z(depth, rays)
    assert rng[1] == pytest.approx(2.0)
    assert rng[0] == pytest.approx(2.0 * np.linalg.norm(rays[0]))
    np.testing.assert_allclose(cv.depth_z_from_range(rng, rays), depth)


def test_quaternion_rejects_zero():
    with pytest.raises(ValueError):
        cv.matrix_from_quat_wxyz([0, 0, 0, 0])


def test_normalised_and_rescaled_pixels_keep_the_image_corners():
    corners = np.array([[-0.5, -0.5], [639.5, 479.5]])  # outer corners of a 640x480 image, OpenCV px
    assert np.array_equal(cv.normalised_from_opencv_pixels(corners, (640, 480)), [[0, 0], [1, 1]])
    assert np.array_equal(cv.normalised_from_opencv_pixels([0.0, 0.0], (640, 480)), [0.5 / 640, 0.5 / 480])
    half = cv.rescaled_opencv_pixels(corners, (0.5, 0.25))
    assert np.array_equal(half, [[-0.5, -0.5], [319.5, 119.5]])
    # pixel centre (1, 1) at scale 2 covers [2, 4] x [2, 4] in the corner frame: centre 3 - 0.5
    assert np.array_equal(cv.rescaled_opencv_pixels([1.0, 1.0], (2, 2)), [2.5, 2.5])
