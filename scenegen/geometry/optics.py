"""Lens and time effects of image formation, as plain data plus their exact geometry (numpy only).

The renderer's sensor (:mod:`scenegen.render.sensor`) applies these while generating rays; the
truth never includes blur: it is cast through the pinhole centre (thin lens), at mid-exposure
(motion blur) or at each row's own time (rolling shutter), for the reference colour channel
(chromatic aberration). See docs/image_formation.md.

Time: ``tau_s`` is seconds relative to the middle of the frame's exposure. With a rolling shutter
row v (OpenCV pixel row, 0 = top) is exposed around ``row_time_s(v)``; the middle of the frame,
``(H - 1) / 2``, is at 0, so the pose in cameras.json is the middle row's.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from scenegen.geometry.camera import Camera
from scenegen.geometry.clock import Composed, ConstantTwist, Shifted, StaticTrajectory
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_rotvec


@dataclass(frozen=True, kw_only=True)
class ThinLens:
    """Thin-lens defocus about our camera model's rays (distortion and skew kept)."""

    f_number: float  # N = focal length / aperture diameter (unitless)
    focus_distance_m: float  # depth (along the optical axis, z) of the plane in focus, metres
    pixel_pitch_um: float  # size of a pixel, micrometres: focal length in metres = fx * pitch

    def aperture_radius_m(self, camera: Camera) -> float:
        return camera.fx * self.pixel_pitch_um * 1e-6 / (2.0 * self.f_number)

    def blur_radius_px(self, camera: Camera, depth_z_m) -> np.ndarray:
        """Radius (px) of the circle of confusion of points at ``depth_z_m``: every ray from the
        aperture through a point at depth Z crosses the focus plane within
        ``A |1/Z_f - 1/Z| Z_f`` of the chief ray, which projects to ``fx A |1/Z_f - 1/Z|``."""
        z = np.asarray(depth_z_m, dtype=np.float64)
        return camera.fx * self.aperture_radius_m(camera) * np.abs(1.0 / self.focus_distance_m - 1.0 / z)


@dataclass(frozen=True, kw_only=True)
class Shutter:
    exposure_s: float = 0.0  # integration time of the motion blur, seconds (0 = instantaneous)
    rolling_readout_s: float = 0.0  # top row to bottom row start delay, seconds (0 = global shutter)

    def row_times_s(self, rows, height: int):
        """Times (seconds from the middle row's, the frame time) of rows ``rows`` (px, continuous
        OpenCV rows, any shape): ``rolling_readout_s * (v / (H - 1) - 0.5)``; 0 for a global shutter."""
        if height <= 1 or self.rolling_readout_s == 0.0:
            return 0.0 * np.asarray(rows, dtype=np.float64)
        return self.rolling_readout_s * (np.asarray(rows, dtype=np.float64) / (height - 1) - 0.5)

    def rows_of_times_s(self, taus_s, height: int):
        """The rows (px, continuous) exposed ``taus_s`` seconds from the middle row: the inverse of
        :meth:`row_times_s` (a rolling shutter only)."""
        return (np.asarray(taus_s, dtype=np.float64) / self.rolling_readout_s + 0.5) * (height - 1)

    # the names other modules use
    row_time_s = row_times_s
    row_of_time = rows_of_times_s


@dataclass(frozen=True, kw_only=True)
class Motion:
    """Constant velocities. For a camera: in its own frame (OpenCV axes, body velocities); for an
    object: in the world, about the object's origin."""

    linear_velocity_mps: tuple[float, float, float] = (0.0, 0.0, 0.0)  # metres / second
    angular_velocity_deg_s: tuple[float, float, float] = (0.0, 0.0, 0.0)  # rotation vector rate, deg / s

    @property
    def angular_velocity_rad_s(self) -> np.ndarray:
        return np.radians(np.asarray(self.angular_velocity_deg_s, dtype=np.float64))

    @property
    def is_static(self) -> bool:
        return not any(self.linear_velocity_mps) and not any(self.angular_velocity_deg_s)

    def delta(self, tau_s: float) -> Rigid3:
        """The displacement after ``tau_s`` seconds: rotation exp(omega tau), translation v tau."""
        R = matrix_from_rotvec(self.angular_velocity_rad_s * tau_s)
        return Rigid3(R, np.asarray(self.linear_velocity_mps, dtype=np.float64) * tau_s)

    def camera_trajectory(self, world_from_cam_mid: Rigid3, time_s: float = 0.0) -> ConstantTwist:
        """The camera's ``world_from_cam`` on the clock (:class:`scenegen.geometry.clock.ConstantTwist`;
        ``time_s``: the frame time, mid-exposure): the poses of :func:`cam_from_world_at`, inverted."""
        return ConstantTwist.from_body_velocities(world_from_cam_mid, time_s, self.linear_velocity_mps,
                                                  self.angular_velocity_rad_s)

    def object_trajectory(self, world_from_object_mid: Rigid3, time_s: float = 0.0) -> ConstantTwist:
        """An object's ``world_from_object`` on the clock: the poses of :func:`world_from_object_at`."""
        return ConstantTwist(world_from_object_mid, float(time_s),
                             np.asarray(self.linear_velocity_mps, np.float64), self.angular_velocity_rad_s)


@dataclass(frozen=True, eq=False)
class PathMotion:
    """A camera (or a rig member) moving along a trajectory within its frame, exactly: the pose
    ``tau_s`` seconds after the frame time is ``trajectory.pose(time_s + tau_s) @ x_from_cam``
    (x = the trajectory's frame: the camera, or the rig). Used like :class:`Motion` (``delta``,
    :func:`cam_from_world_at`, :func:`row_poses`); the renderer's sensor samples it as a table."""

    trajectory: object  # anything with .pose(t) -> Rigid3 world_from_x (geometry.trajectory)
    time_s: float  # the frame's time on the clock (tau = 0)
    x_from_cam: Rigid3 = field(default_factory=Rigid3.identity)

    @property
    def is_static(self) -> bool:
        return False

    @property
    def knot_taus_s(self) -> np.ndarray:
        """(K,) seconds from the frame time at which the path's velocity may jump (its keyframes)."""
        return np.asarray(getattr(self.trajectory, "knot_times_s", ()), np.float64) - self.time_s

    def world_from_cam(self, tau_s: float) -> Rigid3:
        return self.trajectory.pose(self.time_s + float(tau_s)) @ self.x_from_cam

    def world_from_cam_trajectory(self) -> Shifted:
        """The camera's ``world_from_cam`` as a :class:`scenegen.geometry.clock.Trajectory` read in
        seconds from the frame time (tau), velocities and accelerations included."""
        return Shifted(Composed(self.trajectory, StaticTrajectory(self.x_from_cam)), self.time_s)

    def delta(self, tau_s: float) -> Rigid3:
        """The displacement after ``tau_s`` seconds in the camera's own frame at the frame time:
        world_from_cam(tau) = world_from_cam(0) @ delta(tau)."""
        return self.world_from_cam(0.0).inverse() @ self.world_from_cam(tau_s)


def cam_from_world_at(cam_from_world_mid: Rigid3, motion: Motion | None, tau_s: float) -> Rigid3:
    """Camera pose ``tau_s`` seconds after mid-exposure: world_from_cam(tau) = world_from_cam @ delta."""
    if motion is None or motion.is_static or tau_s == 0.0:
        return cam_from_world_mid
    return motion.delta(tau_s).inverse() @ cam_from_world_mid


def row_poses(cam_from_world_mid: Rigid3, motion: Motion | None, shutter: Shutter | None,
              height: int) -> list[Rigid3]:
    """``cam_from_world`` of every image row (rolling shutter): row v at ``shutter.row_time_s(v)``."""
    times = np.zeros(height) if shutter is None else shutter.row_time_s(np.arange(height), height)
    return [cam_from_world_at(cam_from_world_mid, motion, float(t)) for t in times]


def world_from_object_at(world_from_object_mid: Rigid3, motion: Motion | None, tau_s: float) -> Rigid3:
    """Object pose at ``tau_s`` for world-frame velocities about the object's origin."""
    if motion is None or motion.is_static or tau_s == 0.0:
        return world_from_object_mid
    d = motion.delta(tau_s)
    return Rigid3(d.R @ world_from_object_mid.R, world_from_object_mid.t + d.t)


@dataclass(frozen=True, kw_only=True)
class ChromaticAberration:
    """Lateral chromatic aberration as per-channel focal scales about the principal point.

    Green is the reference channel: its camera is the spec's camera and all truth is for it.
    """

    red_focal_scale: float = 1.0  # fx, fy of the red channel = scale * the reference's
    blue_focal_scale: float = 1.0

    def channel_cameras(self, camera: Camera) -> tuple[Camera, Camera, Camera]:
        """(red, green, blue) cameras; green is ``camera`` itself."""
        def scaled(s):
            return camera if s == 1.0 else replace(camera, fx=camera.fx * s, fy=camera.fy * s, skew=camera.skew * s)
        return scaled(self.red_focal_scale), camera, scaled(self.blue_focal_scale)


REFERENCE_CHANNEL = "G"


@dataclass(frozen=True, kw_only=True)
class Optics:
    """Everything of a camera beyond its intrinsics that shapes its images (all optional)."""

    lens: ThinLens | None = None
    shutter: Shutter | None = None
    chromatic_aberration: ChromaticAberration | None = None

    def to_dict(self) -> dict:
        out = {}
        if self.lens is not None:
            out["lens"] = dict(f_number=self.lens.f_number, focus_distance_m=self.lens.focus_distance_m,
                               pixel_pitch_um=self.lens.pixel_pitch_um)
        if self.shutter is not None:
            out["shutter"] = dict(exposure_s=self.shutter.exposure_s, rolling_readout_s=self.shutter.rolling_readout_s,
                                  row_time="rolling_readout_s * (v / (H - 1) - 0.5), middle row at 0")
        if self.chromatic_aberration is not None:
            ca = self.chromatic_aberration
            out["chromatic_aberration"] = dict(red_focal_scale=ca.red_focal_scale, blue_focal_scale=ca.blue_focal_scale,
                                               reference_channel=REFERENCE_CHANNEL)
        return out


def motion_to_dict(motion: Motion | None) -> dict | None:
    if motion is None:
        return None
    if isinstance(motion, PathMotion):
        return {"path": "the view set's trajectory, exactly: world_from_cam(tau) = "
                        "world_from_x(time_s + tau) @ x_from_cam", "time_s": float(motion.time_s),
                "x_from_cam": motion.x_from_cam.to_dict()}
    return {"linear_velocity_mps": list(motion.linear_velocity_mps),
            "angular_velocity_deg_s": list(motion.angular_velocity_deg_s)}

