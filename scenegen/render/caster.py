"""Renders and ray casts of a device scene with every input stated: :class:`Caster`, the third of
the render package's three parts (:mod:`.description` -> :mod:`.device` -> here).

Each call names its camera (a spec camera's sensor, or any :class:`scenegen.geometry.camera.Camera`),
its pose, its clock time ``time_s`` (a sequence's objects placed there; None = frame 0, the
time the description's geometry rests at; a static scene has no time) and, for renders, its
lighting. There is no "current time" to set beforehand: the device is moved to the call's time
first (:meth:`scenegen.render.device.DeviceScene.place_at`). Rolling-shutter casts take their
row poses and the moving objects' per-row poses as values (the pipeline tabulates them,
:func:`scenegen.pipeline.view.rolling_rows`).
"""
from __future__ import annotations

from dataclasses import dataclass

import mitsuba as mi
import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.render import projector, raycast
from scenegen.render.albedo import albedo_pass
from scenegen.render.alone import alone_distances
from scenegen.render.beams import cast_at_times, cast_posed_rays
from scenegen.render.correspond import correspond_in_kernel
from scenegen.render.device import DeviceScene
from scenegen.render.frames import render_ideal, render_view
from scenegen.render.tof import tof_pass
from scenegen.render.truth import camera_rays, truth_pass


@dataclass(frozen=True)
class Caster:
    """Explicit renders and casts of ``device`` (module docstring)."""

    device: DeviceScene

    @property
    def variant(self) -> str:
        """The Mitsuba variant the scene was loaded in."""
        return mi.variant()

    def render(self, camera_name: str, cam_from_world: Rigid3, *, spp: int, seed: int, motion=None,
               light_scales=None, time_s: float | None = None) -> np.ndarray:
        """Linear float32 (H, W, 3) of a view (:func:`scenegen.render.frames.render_view`), every
        projector off."""
        projector.all_off(self.device)
        return render_view(self.device, camera_name, cam_from_world, spp=spp, seed=seed, motion=motion,
                           light_scales=light_scales, time_s=time_s)

    def render_pattern(self, camera_name: str, cam_from_world: Rigid3, projector_name: str,
                       projector_from_world: Rigid3, pattern_values, *, spp: int, seed: int, motion=None,
                       light_scales=None, time_s: float | None = None) -> np.ndarray:
        """Linear float32 (H, W, 3) of a view lit by one projector showing ``pattern_values``
        (its (H_p, W_p[, 3]) image in [0, 1], :func:`scenegen.render.projector.show`) on top of
        the scene's lights at ``light_scales``."""
        projector.show(self.device, projector_name, projector_from_world, pattern_values)
        try:
            return render_view(self.device, camera_name, cam_from_world, spp=spp, seed=seed, motion=motion,
                               light_scales=light_scales, time_s=time_s)
        finally:
            projector.all_off(self.device)

    def render_ideal(self, sensor_camera_name: str, camera, cam_from_world: Rigid3, *, spp: int, seed: int,
                     light_scales=None, time_s: float | None = None) -> np.ndarray:
        """Linear float32 (H, W, 3) of an ideal pinhole (:func:`scenegen.render.frames.render_ideal`)."""
        return render_ideal(self.device, sensor_camera_name, camera, cam_from_world, spp=spp, seed=seed,
                            light_scales=light_scales, time_s=time_s)

    def render_ideal_pattern(self, sensor_camera_name: str, camera, cam_from_world: Rigid3, projector_name: str,
                             projector_from_world: Rigid3, pattern_values, *, spp: int, seed: int,
                             light_scales=None, time_s: float | None = None) -> np.ndarray:
        """:meth:`render_ideal` lit by one projector showing ``pattern_values`` (as
        :meth:`render_pattern`): the rectified images of active IR stereo."""
        projector.show(self.device, projector_name, projector_from_world, pattern_values)
        try:
            return render_ideal(self.device, sensor_camera_name, camera, cam_from_world, spp=spp, seed=seed,
                                light_scales=light_scales, time_s=time_s)
        finally:
            projector.all_off(self.device)

    def truth(self, camera, cam_from_world: Rigid3, row_poses=None, as_stored: bool = False,
              row_moves=None, *, time_s: float | None = None) -> dict[str, np.ndarray]:
        """Per-pixel truth of a camera at a pose and time (:func:`scenegen.render.truth.truth_pass`);
        ``row_poses``: one cam_from_world per row (rolling shutter); ``row_moves`` {object id:
        ((H, 3, 3) R, (H, 3) t world_from_object, (H,) present)}: the moving objects where they
        are at each row's time."""
        dev = self._at(time_s)
        timed = None if row_moves is None else (dev.timed(), row_moves)
        return truth_pass(dev.scene, camera, cam_from_world, dev.id_tables, row_poses=row_poses, as_stored=as_stored,
                          alpha_masked=dev.alpha_masked, timed=timed)

    def tof(self, camera, cam_from_world: Rigid3, freqs_hz, *, spp: int, seed: int, max_bounces: int,
            centre: bool = False, time_s: float | None = None) -> dict[str, np.ndarray]:
        """Per-pixel path sums of a time-of-flight camera with its co-located emitter at a pose and
        time: phasors per modulation frequency, direct light alone, first-hit range spread
        (:func:`scenegen.render.tof.tof_pass`)."""
        if mi.variant().startswith("scalar"):
            raise NotImplementedError("a ToF camera needs a vectorised Mitsuba variant (llvm_ad_rgb / cuda_ad_rgb)")
        return tof_pass(self._at(time_s).scene, camera, cam_from_world, freqs_hz, spp=spp, seed=seed,
                        max_bounces=max_bounces, centre=centre)

    def albedo(self, camera, cam_from_world: Rigid3, *, time_s: float | None = None) -> np.ndarray:
        """(H, W, 3) float32 diffuse albedo per pixel centre (:func:`scenegen.render.albedo.albedo_pass`)."""
        dev = self._at(time_s)
        return albedo_pass(dev.scene, camera, cam_from_world, dev.alpha_masked)

    def camera_rays(self, camera) -> np.ndarray:
        """(H*W, 3) float64 unit rays of the camera's pixel centres, row-major, as the truth pass
        casts them (:func:`scenegen.render.truth.camera_rays`, read-only)."""
        return camera_rays(camera)

    def visible_from(self, center_world, points_world, moves=None, *, time_s: float | None = None) -> np.ndarray:
        """(N,) bool visibility of world points from a centre (3,), or each from its own centre
        (N, 3) (:func:`scenegen.render.raycast.visible_from`) at ``time_s``; ``moves`` {object id:
        ((N, 3, 3) R, (N, 3) t world_from_object, (N,) present)}: the moving objects where they are
        when each point is seen (rolling shutter)."""
        dev = self._at(time_s)
        timed = None if moves is None else (dev.timed(), moves)
        return raycast.visible_from(dev.scene, center_world, points_world, alpha_masked=dev.alpha_masked, timed=timed)

    @property
    def kernel_correspondences(self) -> bool:
        """:meth:`correspond` applies: a vectorised variant and no alpha masks (their holes need
        the visibility cast of :meth:`visible_from`)."""
        return not self.device.alpha_masked and not mi.variant().startswith("scalar")

    def correspond(self, points_world, camera, cam_from_world: Rigid3, *, time_s: float | None = None):
        """Correspondences of truth points (H, W, 3) (float64, NaN = no surface) in a view at
        ``time_s``, in one kernel (:mod:`scenegen.render.correspond`: the definition of
        :func:`scenegen.crossview.correspondence.correspond`); needs :attr:`kernel_correspondences`."""
        return correspond_in_kernel(self._at(time_s).scene, points_world, camera, cam_from_world)

    def surface_points(self, camera, cam_from_world: Rigid3, uv, *, time_s: float | None = None) -> np.ndarray:
        """(N, 3) world points seen through sub-pixel positions (:func:`scenegen.render.raycast.surface_points`)."""
        dev = self._at(time_s)
        return raycast.surface_points(dev.scene, camera, cam_from_world, uv, dev.alpha_masked)[0]

    def surface_hits(self, camera, cam_from_world: Rigid3, uv, rows=None, moves=None, *,
                     time_s: float | None = None):
        """((N, 3) world points seen through sub-pixel positions, (N,) their object ids or None):
        :meth:`surface_points` through a rolling shutter (``rows``: the camera's world_from_cam
        per row; ``moves``: the moving objects at the positions' rows, then the ids come back)."""
        dev = self._at(time_s)
        timed = None if moves is None else (dev.timed(), moves)
        return raycast.surface_points(dev.scene, camera, cam_from_world, uv, dev.alpha_masked, rows, timed)

    def cast_at_times(self, origins_world, directions_world, times_s):
        """((N,) range m (inf: none), (N, 3) unit normals, (N,) object ids, (N,) instance ids) of
        rays (N, 3) each cast at its own time (N,) s with the moving objects there
        (:func:`scenegen.render.beams.cast_at_times`: a LiDAR's beams)."""
        return cast_at_times(self.device, origins_world, directions_world, times_s)
    def alone_distances(self, object_id: int, world_from_object: Rigid3, origin_world, directions_world) -> np.ndarray:
        """(N,) float64 distances along unit rays to one object alone at ``world_from_object``
        (+inf: missed; :func:`scenegen.render.alone.alone_distances`)."""
        return alone_distances(self.device, object_id, world_from_object, origin_world, directions_world)

    def first_hit_distance(self, origin_world, directions_world, *, time_s: float | None = None) -> np.ndarray:
        """(N,) float64 distances along unit rays to the first surface of the scene at ``time_s``
        (+inf: missed; :func:`scenegen.render.raycast.first_hit_distance`)."""
        dev = self._at(time_s)
        return raycast.first_hit_distance(dev.scene, origin_world, directions_world, dev.alpha_masked)[0]

    def cast_beams(self, rays):
        """:class:`scenegen.spec.sensors.lidar_beams.RayHits` of a LiDAR's posed rays, each cast at
        its own time, in one kernel (:func:`scenegen.render.beams.cast_posed_rays`: the
        ``BeamCast`` a sweep takes)."""
        return cast_posed_rays(self.device, rays)

    def _at(self, time_s: float | None) -> DeviceScene:
        self.device.place_at(time_s)
        return self.device
