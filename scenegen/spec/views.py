"""View sets -> camera poses.

Each placement yields ``world_from_X`` poses, X being the camera or, for a rig view set, the rig
frame; a rig's member cameras are then ``world_from_cam = world_from_rig @ rig_from_cam``.
Placements look at their targets with :func:`scenegen.geometry.pose.look_at` (OpenCV axes, world up +z by
default).

Naming: every placement (one camera pose, or one rig pose shared by its members) gets the next
``frame_index``, counted over all view sets in order from 0. A view is named
``{prefix}_{frame_index:04d}`` for a lone camera and ``{prefix}_{member}_{frame_index:04d}`` for a
rig member, where ``prefix`` is the view set's ``name`` or else its camera / rig name. Names are
unique because frame indices are, and stable as long as the earlier view sets do not change.
More than 10,000 frames widen the number so that names still sort in frame order.
"""
from __future__ import annotations

import math

import numpy as np

from scenegen.errors import SpecError
from scenegen.geometry.optics import Motion, PathMotion
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.spec import model as m
from scenegen.spec.sensors import SENSOR_KINDS, VIEWS, RigFrame

#: Random eyes closer than this to the target, or looking (nearly) along up, are redrawn.
_MIN_SEPARATION_M = 1e-6
_MIN_SIN_UP = 1e-3  # sine of the smallest accepted angle between view direction and up
_MAX_REDRAWS = 1000


def resolve_views(spec: m.SceneSpec) -> tuple[m.View, ...]:
    """All views of ``spec``, in order: view set by view set, placement by placement, and within
    a rig placement member by member. Deterministic (random view sets use their seeds)."""
    per_set = [placement_poses(vs) for vs in spec.view_sets]  # world_from_X lists
    n_frames = sum(len(p) for p in per_set)
    width = max(4, len(str(max(n_frames - 1, 0))))
    views: list[m.View] = []
    frame = 0
    for set_index, (vs, poses) in enumerate(zip(spec.view_sets, per_set)):
        scales = view_set_light_scales(spec, vs)
        times = vs.placement.times_s if isinstance(vs.placement, m.TrajectoryPath) else None
        for k, world_from_x in enumerate(poses):
            time_s = None if times is None else float(times[k])
            motion = vs.motion if times is None else path_motion(spec, vs, time_s)
            if vs.camera is not None:
                views.append(m.View(name=f"{vs.prefix}_{frame:0{width}d}", camera=vs.camera,
                                    cam_from_world=world_from_x.inverse(), frame_index=frame,
                                    view_set=set_index, motion=motion, light_scales=scales,
                                    time_s=time_s))
            else:
                rig = spec.rigs[vs.rig]
                for member in view_members(rig):
                    world_from_cam = world_from_x @ member.rig_from_cam
                    views.append(m.View(
                        name=f"{vs.prefix}_{member.name}_{frame:0{width}d}", camera=member.camera,
                        cam_from_world=world_from_cam.inverse(), rig=rig.name,
                        rig_member=member.name, frame_index=frame, view_set=set_index,
                        motion=member_motion(motion, member.rig_from_cam), light_scales=scales,
                        time_s=time_s))
            frame += 1
    return tuple(views)


def view_members(rig: m.Rig) -> tuple[m.RigMember, ...]:
    """The members of a rig that make views (of a kind that produces views: its cameras)."""
    return tuple(mb for mb in rig.members if SENSOR_KINDS[mb.kind].produces == VIEWS)


def rig_frames(spec: m.SceneSpec) -> tuple[tuple[m.ViewSet, tuple[RigFrame, ...]], ...]:
    """Every rig view set with its frames (a rig at a time), in view set order; frame indices
    and times as :func:`resolve_views` gives the views of those frames."""
    out, frame = [], 0
    for set_index, vs in enumerate(spec.view_sets):
        poses = placement_poses(vs)
        times = vs.placement.times_s if isinstance(vs.placement, m.TrajectoryPath) else (None,) * len(poses)
        if vs.rig is not None:
            out.append((vs, tuple(RigFrame(rig=vs.rig, view_set=set_index, frame_index=frame + k,
                                           time_s=None if t is None else float(t), world_from_rig=pose)
                                  for k, (pose, t) in enumerate(zip(poses, times)))))
        frame += len(poses)
    return tuple(out)


def view_set_light_scales(spec: m.SceneSpec, vs: m.ViewSet) -> tuple[float, ...] | None:
    """The view set's factor on each spec light's power, in spec order (0 = off; a light its
    ``lights`` does not name is off), or None when it has no ``lights`` (every light at 1)."""
    if vs.lights is None:
        return None
    return tuple(float(vs.lights.get(light.name, 0.0)) for light in spec.lights)


def light_scales_dict(spec: m.SceneSpec, scales: tuple[float, ...] | None) -> dict[str, float]:
    """{light name: factor} for every spec light, in spec order (None = every light at 1)."""
    if scales is None:
        scales = (1.0,) * len(spec.lights)
    return {light.name: float(k) for light, k in zip(spec.lights, scales)}


def placement_poses(vs: m.ViewSet) -> list[Rigid3]:
    """world_from_X for every placement of a view set (X = camera or rig frame)."""
    p = vs.placement
    if isinstance(p, m.PoseList):
        return list(p.world_from_cam)
    if isinstance(p, m.TrajectoryPath):
        traj = p.trajectory.trajectory()
        return [traj.pose(t) for t in p.times_s]
    if isinstance(p, m.LookAtList):
        aims = [(e.eye, e.target, e.up) for e in p.entries]
    elif isinstance(p, m.Orbit):
        aims = [(eye, p.center, m.WORLD_UP) for eye in orbit_eyes(p)]
    elif isinstance(p, (m.LinePath, m.CirclePath)):
        eyes = line_eyes(p) if isinstance(p, m.LinePath) else circle_eyes(p)
        aims = [(eye, p.target, p.up) for eye in eyes]
    elif isinstance(p, m.RandomPoses):
        aims = [(e, t, p.up) for e, t in zip(*random_eyes_targets(p, vs))]
    else:
        raise TypeError(f"unknown placement {type(p).__name__}")
    poses = []
    for k, (eye, target, up) in enumerate(aims):
        try:
            poses.append(look_at(eye, target, up))
        except ValueError as e:  # eye == target, or looking along up
            raise SpecError.at(vs.where, f"cannot place view {k} of view set {vs.prefix!r} "
                               f"(eye {np.round(eye, 6).tolist()}, target "
                               f"{np.round(target, 6).tolist()}): {e}") from None
    return poses


def orbit_eyes(p: m.Orbit) -> np.ndarray:
    """(len(elevations) * count, 3) eyes, metres: elevation by elevation, azimuth from
    start_azimuth_deg counter-clockwise about +z (from +x toward +y)."""
    eyes = []
    for el in np.radians(p.elevations_deg):
        for k in range(p.count):
            az = math.radians(p.start_azimuth_deg) + 2 * math.pi * k / p.count
            eyes.append(np.asarray(p.center) + p.radius_m * np.array(
                [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]))
    return np.array(eyes).reshape(-1, 3)


def line_eyes(p: m.LinePath) -> np.ndarray:
    """(count, 3) eyes evenly spaced from start to end, both included (count 1: start)."""
    s = np.linspace(0.0, 1.0, p.count) if p.count > 1 else np.zeros(1)
    return np.asarray(p.start) + s[:, None] * (np.asarray(p.end) - np.asarray(p.start))


def circle_eyes(p: m.CirclePath) -> np.ndarray:
    """(count, 3) eyes on the circle, counter-clockwise about +z, the start not repeated."""
    az = math.radians(p.start_azimuth_deg) + 2 * math.pi * np.arange(p.count) / p.count
    return np.asarray(p.center) + np.stack(
        [p.radius_m * np.cos(az), p.radius_m * np.sin(az), np.full(p.count, p.height_m)], axis=1)


def random_eyes_targets(p: m.RandomPoses, vs: m.ViewSet | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
    """((count, 3) eyes, (count, 3) targets), uniform in their boxes, drawn with
    ``numpy.random.default_rng(seed)`` in the order eye, target per view. Draws with the eye
    within max(min_distance_m, 1e-6) of the target, or looking within 0.06 degrees of up, are
    drawn again (at most 1000 times per view; then a SpecError at the view set)."""
    rng = np.random.default_rng(p.seed)
    up = np.asarray(p.up, float)
    up = up / np.linalg.norm(up) if np.linalg.norm(up) > 0 else up
    eyes, targets = [], []
    for _ in range(p.count):
        for _ in range(_MAX_REDRAWS):
            eye = rng.uniform(p.eye_min, p.eye_max)
            target = rng.uniform(p.target_min, p.target_max)
            d = target - eye
            dist = np.linalg.norm(d)
            if dist >= max(p.min_distance_m, _MIN_SEPARATION_M) and \
                    np.linalg.norm(np.cross(d / dist, up)) >= _MIN_SIN_UP:
                break
        else:
            raise SpecError.at(vs.where if vs else None,
                               f"no eye/target pair at least {p.min_distance_m:g} m apart and "
                               f"not along up in {_MAX_REDRAWS} draws; check eye_box, target "
                               f"and min_distance_m")
        eyes.append(eye)
        targets.append(target)
    return np.array(eyes).reshape(-1, 3), np.array(targets).reshape(-1, 3)


def _timed(spec: m.SceneSpec, camera: str) -> bool:
    shutter = getattr(spec.cameras[camera].optics, "shutter", None)
    return shutter is not None and (shutter.exposure_s > 0 or shutter.rolling_readout_s > 0)


def path_motion(spec: m.SceneSpec, vs: m.ViewSet, time_s: float):
    """Within one frame's exposure and readout a camera (or rig frame) on a trajectory moves along
    the trajectory itself (:class:`scenegen.geometry.optics.PathMotion`; the renderer and the
    per-row truth sample the same curve). None when no camera of the view set has a shutter with
    an exposure or a readout time (nothing would use it)."""
    cams = [vs.camera] if vs.camera is not None else [mb.camera for mb in view_members(spec.rigs[vs.rig])]
    if not any(_timed(spec, c) for c in cams):
        return None
    return PathMotion(trajectory=vs.placement.trajectory.trajectory(), time_s=float(time_s))


def member_motion(rig_motion, rig_from_cam: Rigid3):
    """A rig's body velocities seen by one member camera: omega_cam = R^T omega,
    v_cam = R^T (v + omega x t), with rig_from_cam = (R, t)."""
    if rig_motion is None:
        return None
    if isinstance(rig_motion, PathMotion):  # the member on the rig's path
        return PathMotion(trajectory=rig_motion.trajectory, time_s=rig_motion.time_s, x_from_cam=rig_from_cam)
    R, t = rig_from_cam.R, rig_from_cam.t
    w = np.radians(np.asarray(rig_motion.angular_velocity_deg_s, dtype=np.float64))
    v = np.asarray(rig_motion.linear_velocity_mps, dtype=np.float64)
    return Motion(linear_velocity_mps=tuple(R.T @ (v + np.cross(w, t))),
                  angular_velocity_deg_s=tuple(np.degrees(R.T @ w)))
