"""The drop (scenegen.physics): release poses, and MuJoCo's settled poses against closed forms --
a box released upright rests flat at top + h/2, an off-centre mesh's pose is its object frame's
(not MuJoCo's centre of mass frame), the same input gives the same bits, a settled state stays."""
import numpy as np
import pytest

from scenegen.assets import shapes
from scenegen.geometry.pose import Rigid3
from scenegen.physics import (
    Body, DropError, DropSettings, bounding_radius, release_poses, settle, support_hull,
)
from scenegen.physics.drop import mjcf

TABLE_TOP_Z = 0.72
SETTINGS = DropSettings(friction=0.8, settle_s=3.0, rest_speed_m_s=1e-3)


def table():
    return support_hull(shapes.box((0.8, 0.6, 0.04)).vertices, Rigid3(np.eye(3), [0, 0, 0.7]), "table")


def yaw(deg):
    a = np.radians(deg)
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1.0]])


def test_release_poses_keep_the_spheres_apart_inside_their_regions():
    radii = [0.05, 0.03, 0.04, 0.06] * 5
    regions = [((-0.1, -0.1), (0.1, 0.1))] * len(radii)  # crowded: some are stacked above the rest
    poses = release_poses(radii, [np.eye(3)] * len(radii), regions, 0.7, 0.02, "random", np.random.default_rng(3))
    c = np.array([p.t for p in poses])
    gaps = np.linalg.norm(c[:, None] - c[None], axis=2) - (np.add.outer(radii, radii))
    assert (gaps[~np.eye(len(radii), dtype=bool)] >= 0).all()
    assert (np.abs(c[:, :2]) <= 0.1).all()
    assert (c[:, 2] - radii >= 0.72 - 1e-12).all()  # every sphere clear of the top (0.7 + 0.02)
    again = release_poses(radii, [np.eye(3)] * len(radii), regions, 0.7, 0.02, "random", np.random.default_rng(3))
    assert all((a.matrix == b.matrix).all() for a, b in zip(poses, again))


def test_yaw_keeps_the_written_up_axis():
    R0 = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])  # object +z along world -y
    poses = release_poses([0.1] * 3, [R0] * 3, [((0, 0), (1, 1))] * 3, 0.0, 0.0, "yaw", np.random.default_rng(0))
    turns = [p.R @ R0.T for p in poses]  # each a turn about world +z alone
    for T in turns:
        assert np.allclose(T, yaw(np.degrees(np.arctan2(T[1, 0], T[0, 0]))), atol=1e-12)
    assert len({round(float(np.arctan2(T[1, 0], T[0, 0])), 6) for T in turns}) == 3  # drawn, not fixed


def test_a_box_released_upright_rests_flat_on_the_top():
    box = shapes.box((0.1, 0.06, 0.04)).vertices
    out = settle([Body("b", box, Rigid3(yaw(30), [0.05, 0.02, 0.8]))], table(), SETTINGS)
    assert out.at_rest and out.time_s < 3.0
    (p,) = out.poses
    assert abs(p.t[2] - (TABLE_TOP_Z + 0.02)) < 5e-5  # top + h/2, within 0.05 mm of soft contact
    assert abs(p.R[2, 2] - 1.0) < 1e-6  # still upright
    assert np.allclose(p.t[:2], [0.05, 0.02], atol=1e-4)  # no sideways drift from a flat landing


def test_the_pose_is_the_object_frame_not_the_centre_of_mass():
    # a box whose vertices lie off the object origin: MuJoCo recentres meshes on their centre of
    # mass internally; the settled pose must still map object vertices onto the resting box
    offset = np.array([0.2, -0.1, 0.05])
    box = shapes.box((0.08, 0.08, 0.04)).vertices + offset
    out = settle([Body("b", box, Rigid3(np.eye(3), [-0.2, 0.1, 0.75]))], table(), SETTINGS)
    world = out.poses[0].apply(box)
    assert abs(world[:, 2].min() - TABLE_TOP_Z) < 5e-5 and abs(world[:, 2].max() - TABLE_TOP_Z - 0.04) < 5e-5
    assert np.allclose(world.mean(axis=0)[:2], [0.0, 0.0], atol=1e-4)


def test_same_input_same_bits_and_a_settled_state_stays():
    rng = np.random.default_rng(1)
    parts = [shapes.sphere(0.03).vertices, shapes.cylinder(0.02, 0.07).vertices, shapes.torus(0.03, 0.01).vertices,
             shapes.box((0.05, 0.04, 0.03)).vertices]
    radii = [bounding_radius(v) for v in parts]
    rel = release_poses(radii, [np.eye(3)] * 4, [((-0.2, -0.15), (0.2, 0.15))] * 4, TABLE_TOP_Z, 0.03, "random", rng)
    bodies = [Body(f"o{i}", v, p) for i, (v, p) in enumerate(zip(parts, rel))]
    a = settle(bodies, table(), SETTINGS)
    b = settle(bodies, table(), DropSettings(friction=0.8, settle_s=3.0 + 1e-9, rest_speed_m_s=1e-3))  # no cache hit
    assert a.at_rest and all((x.matrix == y.matrix).all() for x, y in zip(a.poses, b.poses))
    # released at rest where they settled, nothing moves by more than 0.05 mm in 0.5 s
    again = settle([Body(o.name, o.vertices, p) for o, p in zip(bodies, a.poses)], table(),
                   DropSettings(friction=0.8, settle_s=0.5, rest_speed_m_s=1e-9))
    moved = max(np.abs(q.apply(v) - p.apply(v)).max() for v, p, q in zip(parts, a.poses, again.poses))
    assert moved < 5e-5


def test_the_model_text_writes_floats_exactly():
    v = shapes.box((0.1, 0.1, 0.1)).vertices + 1 / 3
    hull = support_hull(v, Rigid3.identity(), "s")
    text = mjcf([hull], [Rigid3(np.eye(3), [0.1, 0.2, 1 / 7])], hull, 0.8)
    assert repr(1 / 7) in text and repr(float(hull.vertices[0, 0])) in text


def test_flat_objects_are_refused_and_flat_supports_thickened():
    with pytest.raises(DropError, match="no volume"):
        settle([Body("p", shapes.plane((0.1, 0.1)).vertices, Rigid3(np.eye(3), [0, 0, 1]))], table(), SETTINGS)
    slab = support_hull(shapes.plane((1.0, 1.0)).vertices, Rigid3(np.eye(3), [0, 0, 0.5]), "floor")
    assert np.allclose(slab.bounds, [[-0.5, -0.5, 0.49], [0.5, 0.5, 0.5]])
