"""Objects dropped onto a static support and stepped with MuJoCo until every one rests.

Each dropped object is a free rigid body whose collision shape is the convex hull (trimesh) of
its scaled object-frame mesh, its body frame the object frame, so the settled body pose is the
object's ``world_from_object``. The support is a static convex hull in the world (a flat one, a
plane or a board, thickened below its face). Gravity is -z (the world is Z-up).

The engine settings are fixed here (one place), chosen and measured on 20 mixed objects on a
box: stiff contacts (``solref`` time constant 4 ms, twice the time step) sink a resting object
into the support by under 0.01 mm (MuJoCo's default: 0.1-0.3 mm); rolling and torsional
friction and three no-slip iterations bring spheres and cylinders to rest (velocities ~1e-14)
within about 2 s of simulated time, where without them they creep at mm/s for ever.

MuJoCo steps single-threaded and is deterministic for identical inputs: the model is built from
text in which every float is its shortest round-trip repr, so the same release poses and meshes
give the same bits (tests/scenegen/physics/test_drop.py runs it in two processes).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import trimesh

from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_quat_wxyz, quat_wxyz_from_matrix

#: Gravity along world -z (m/s^2).
GRAVITY_M_S2 = 9.81
#: Simulation time step (s); the contact time constant below is twice it (MuJoCo's stability rule).
TIMESTEP_S = 0.002
#: Density of every dropped object (kg/m^3): only mass ratios matter to where objects come to rest.
DENSITY_KG_M3 = 500.0
#: MuJoCo contact softness: (time constant s, damping ratio) and (dmin, dmax, width m).
CONTACT_SOLREF = (0.004, 1.0)
CONTACT_SOLIMP = (0.95, 0.99, 0.0005)
#: Torsional and rolling friction (m), beside the spec's sliding coefficient (condim 6).
TORSIONAL_FRICTION_M = 0.005
ROLLING_FRICTION_M = 0.002
NOSLIP_ITERATIONS = 3
#: A flat support (zero extent along its own z) is thickened this much below its face.
FLAT_SUPPORT_THICKNESS_M = 0.01
#: Steps between two rest checks, and how long every object must stay below the rest speed.
CHECK_EVERY_STEPS = 10
REST_HOLD_S = 0.2


class DropError(ValueError):
    """A drop that cannot be simulated (degenerate hull, an engine error, a diverged state)."""

    def __init__(self, message: str, body: str | None = None):
        super().__init__(message)
        self.body = body  # the body's name, where one is to blame


@dataclass(frozen=True, eq=False)
class Body:
    """A dropped object: ``vertices`` (N, 3) float64 metres in its object frame, scale applied;
    ``release`` its world_from_object when released at rest."""

    name: str
    vertices: np.ndarray
    release: Rigid3


@dataclass(frozen=True)
class DropSettings:
    friction: float  # sliding (Coulomb) coefficient of every contact
    settle_s: float  # simulated time at most (s)
    rest_speed_m_s: float  # at rest: no point of any object faster than this (m/s)


@dataclass(frozen=True, eq=False)
class Settled:
    """The end of a drop: ``poses`` (world_from_object per body, in order), the simulated
    ``time_s``, ``point_speed_m_s`` (n,) a bound on the fastest point of each body (|v| + |w| r,
    r the body's largest vertex distance from its origin), and whether all of them stayed below
    the rest speed for REST_HOLD_S (``at_rest``)."""

    poses: tuple[Rigid3, ...]
    time_s: float
    point_speed_m_s: np.ndarray
    at_rest: bool


def engine_version() -> str:
    # MuJoCo on use: only a spec with `placement:` needs it (~0.2 s to import)
    import mujoco

    return f"mujoco {mujoco.__version__}"


def convex_hull(vertices: np.ndarray, what: str) -> trimesh.Trimesh:
    """The convex hull of (N, 3) vertices; DropError when it has no volume."""
    try:
        hull = trimesh.convex.convex_hull(np.asarray(vertices, dtype=np.float64))
    except Exception as e:  # qhull refuses flat or collinear point sets
        raise DropError(f"{what} has no volume to collide with ({type(e).__name__})") from None
    if not hull.is_volume or hull.volume <= 0:
        raise DropError(f"{what} has no volume to collide with (a flat or degenerate shape)")
    return hull


def support_hull(vertices: np.ndarray, world_from_object: Rigid3, name: str) -> trimesh.Trimesh:
    """The support's collision shape in the world: the hull of its scaled object-frame
    ``vertices`` placed by ``world_from_object``; flat in its own z (a plane, a board) it is
    thickened FLAT_SUPPORT_THICKNESS_M below its face first."""
    v = np.asarray(vertices, dtype=np.float64)
    if np.ptp(v[:, 2]) == 0:
        v = np.vstack([v, v - [0.0, 0.0, FLAT_SUPPORT_THICKNESS_M]])
    return convex_hull(world_from_object.apply(v), f"the support {name!r}")


def _floats(a) -> str:
    return " ".join(repr(float(x)) for x in np.ravel(a))


def _mesh(name: str, hull: trimesh.Trimesh) -> str:
    faces = " ".join(str(int(i)) for i in np.ravel(hull.faces))
    return f'<mesh name="{name}" vertex="{_floats(hull.vertices)}" face="{faces}"/>'


def mjcf(hulls: list[trimesh.Trimesh], releases: list[Rigid3], support: trimesh.Trimesh,
         friction: float) -> str:
    """The MuJoCo model (MJCF text) of a drop: body ``b<i>`` with mesh ``m<i>`` per dropped
    object, the support a static world geom. Every float as its shortest round-trip repr."""
    contact = (f'friction="{_floats([friction, TORSIONAL_FRICTION_M, ROLLING_FRICTION_M])}" '
               f'condim="6" solref="{_floats(CONTACT_SOLREF)}" solimp="{_floats(CONTACT_SOLIMP)}"')
    out = ['<mujoco model="drop">',
           f'<option timestep="{TIMESTEP_S!r}" gravity="0 0 {-GRAVITY_M_S2!r}" integrator="implicitfast" '
           f'cone="elliptic" impratio="10" noslip_iterations="{NOSLIP_ITERATIONS}"/>',
           f'<default><geom {contact} density="{DENSITY_KG_M3!r}"/></default>',
           "<asset>", _mesh("support", support)]
    out += [_mesh(f"m{i}", h) for i, h in enumerate(hulls)]
    out += ["</asset>", "<worldbody>", '<geom name="support" type="mesh" mesh="support"/>']
    for i, pose in enumerate(releases):
        q = quat_wxyz_from_matrix(pose.R)
        out.append(f'<body name="b{i}" pos="{_floats(pose.t)}" quat="{_floats(q)}"><freejoint/>'
                   f'<geom type="mesh" mesh="m{i}"/></body>')
    out += ["</worldbody>", "</mujoco>"]
    return "\n".join(out)


def settle(bodies: list[Body], support: trimesh.Trimesh, settings: DropSettings) -> Settled:
    """Release ``bodies`` above ``support`` (its world collision hull, :func:`support_hull`) and
    step until every one has stayed at rest for REST_HOLD_S or ``settings.settle_s`` is spent."""
    hulls = [convex_hull(b.vertices, f"object {b.name!r}") for b in bodies]
    radii = tuple(float(np.linalg.norm(b.vertices, axis=1).max()) for b in bodies)
    xml = mjcf(hulls, [b.release for b in bodies], support, settings.friction)
    qpos, time_s, speed, at_rest = _simulate(xml, radii, settings.settle_s, settings.rest_speed_m_s)
    poses = tuple(Rigid3(matrix_from_quat_wxyz(q[3:7]), q[:3]) for q in qpos)
    return Settled(poses=poses, time_s=time_s, point_speed_m_s=np.array(speed), at_rest=at_rest)


def point_speeds(qvel: np.ndarray, radii) -> np.ndarray:
    """(n,) |v| + |w| r per free body from MuJoCo's qvel (n * 6: linear, then angular)."""
    v = np.asarray(qvel, dtype=np.float64).reshape(-1, 6)
    return np.linalg.norm(v[:, :3], axis=1) + np.linalg.norm(v[:, 3:], axis=1) * np.asarray(radii)


@functools.lru_cache(maxsize=4)  # validate, render and to_yaml round trips parse a spec again
def _simulate(xml: str, radii: tuple, settle_s: float, rest_speed: float):
    # MuJoCo on use: only a spec with `placement:` needs it
    import mujoco

    try:
        model = mujoco.MjModel.from_xml_string(xml)
    except ValueError as e:
        raise DropError(f"MuJoCo refused the model: {str(e).splitlines()[0]}") from None
    data = mujoco.MjData(model)
    n_max = math.ceil(settle_s / TIMESTEP_S)
    hold = math.ceil(REST_HOLD_S / (CHECK_EVERY_STEPS * TIMESTEP_S))
    held, steps, speed = 0, 0, point_speeds(data.qvel, radii)
    while steps < n_max and held < hold:
        mujoco.mj_step(model, data, nstep=CHECK_EVERY_STEPS)
        steps += CHECK_EVERY_STEPS
        if not np.all(np.isfinite(data.qpos)) or data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:
            raise DropError(f"the simulation diverged at {steps * TIMESTEP_S:.3f} s (simulated)")
        speed = point_speeds(data.qvel, radii)
        held = held + 1 if speed.max() < rest_speed else 0
    qpos = tuple(tuple(float(x) for x in data.qpos[7 * i: 7 * i + 7]) for i in range(len(radii)))
    return qpos, steps * TIMESTEP_S, tuple(float(s) for s in speed), held >= hold
