"""Rendering images of a device scene: a view with its camera's lens and time effects, and the
ideal rectified renders of a stereo pair. Linear float32 RGB out; encoding is the pipeline's."""
from __future__ import annotations

import mitsuba as mi
import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.render.lights import set_lighting
from scenegen.render.animate import place_animated
from scenegen.render.objects import place_moving_objects
from scenegen.spec.model.render import effective_spp


def render_view(built, camera_name: str, cam_from_world: Rigid3, *, spp: int, seed: int,
                motion=None, light_scales=None, time_s: float | None = None) -> np.ndarray:
    """Linear float32 (H, W, 3) radiance of one view of a device scene
    (:class:`scenegen.render.device.DeviceScene`), with the camera's lens and time effects.

    ``cam_from_world`` is the mid-exposure pose; ``motion`` the camera's own velocities;
    ``time_s`` the clock time of a sequence's frame (None: frame 0; its objects placed there);
    ``light_scales`` the factor on each spec light's power (:func:`set_lighting`; None = every
    light at its spec power, whatever an earlier view used). Moving objects are rendered in
    ``built.motion_subframes`` sub-frames, each with the objects at one time, and they are left
    at mid-exposure, where the truth is cast. With a global shutter each sub-frame is a slice of
    the exposure with spp / sub-frames samples, averaged; with a rolling shutter
    (:func:`_time_bins`) each is a slice of the frame's whole time span, rendered at the full spp
    with only the samples whose time (their row's time within the exposure) falls in the slice,
    summed. Chromatic aberration renders each colour channel with its own camera.
    """
    set_lighting(built, light_scales)
    built.place_at(time_s)
    t_frame = built.time_or_rest(time_s)
    camera = built.cameras[camera_name]
    optics = built.optics.get(camera_name)
    sensor = built.sensors[camera_name]
    ca = getattr(optics, "chromatic_aberration", None)
    channel_cameras = ca.channel_cameras(camera) if ca is not None else (camera,)
    shutter = getattr(optics, "shutter", None)
    exposure = 0.0 if shutter is None else shutter.exposure_s
    bins = _time_bins(built, shutter, camera.height)
    n_sub = len(bins) if bins else (built.motion_subframes if exposure > 0 else 1)
    # asked as the count the sampler takes (the same samples; no Mitsuba WARN about rounding)
    sub_spp = effective_spp(built.sampler, max(1, int(spp) // n_sub) if not bins else int(spp))
    out = np.zeros((camera.height, camera.width, 3), np.float64)
    for k in range(n_sub):
        if n_sub > 1:
            tau = bins[k][2] if bins else ((k + 0.5) / n_sub - 0.5) * exposure
            place_moving_objects(built, tau)
            if built.animated:  # a sequence's objects follow their trajectories within the exposure
                place_animated(built, t_frame + tau)
        window = (0.0, 1.0) if bins else (k / n_sub, (k + 1) / n_sub)
        for c, cam in enumerate(channel_cameras):
            sensor.set_camera(cam, cam_from_world, optics, motion, time_window=window,
                              time_bin=bins[k][:2] if bins else None)
            img = np.array(mi.render(built.scene, sensor=sensor, spp=sub_spp, seed=(int(seed) + k) % 2**32),
                           dtype=np.float32)[..., :3]
            if len(channel_cameras) == 3:
                out[..., c] += img[..., c]
            else:
                out += img
    if n_sub > 1:
        place_moving_objects(built, 0.0)
        if built.animated:
            place_animated(built, t_frame)
    return (out if bins else out / n_sub).astype(np.float32)


def _time_bins(built, shutter, height: int) -> list[tuple[float, float, float]]:
    """Rolling-shutter sub-frames of a scene with moving objects: ``built.motion_subframes``
    slices (lo, hi, centre), seconds from mid-exposure, of the frame's whole time span (the first
    row's exposure start to the last row's end; the outer edges open); the objects are placed at
    each slice's centre. Empty for a global shutter or a scene where nothing moves."""
    if shutter is None or shutter.rolling_readout_s == 0 or not (built.moving or built.animated):
        return []
    lo = float(shutter.row_time_s(-0.5, height)) - 0.5 * shutter.exposure_s
    hi = float(shutter.row_time_s(height - 0.5, height)) + 0.5 * shutter.exposure_s
    n = built.motion_subframes
    edges = np.linspace(lo, hi, n + 1)
    return [(-np.inf if k == 0 else float(edges[k]), np.inf if k == n - 1 else float(edges[k + 1]),
             float(0.5 * (edges[k] + edges[k + 1]))) for k in range(n)]


def render_ideal(built, sensor_camera_name: str, camera, cam_from_world: Rigid3, *, spp: int, seed: int,
                 light_scales=None, time_s: float | None = None) -> np.ndarray:
    """Linear float32 (H, W, 3) of ``camera`` (a pinhole of the sensor's size, e.g. a rectified
    view) through the sensor of ``sensor_camera_name`` at clock time ``time_s`` (None: frame 0):
    no lens, motion or aberration."""
    set_lighting(built, light_scales)
    built.place_at(time_s)
    sensor = built.sensors[sensor_camera_name]
    sensor.set_camera(camera, cam_from_world)
    img = mi.render(built.scene, sensor=sensor, spp=effective_spp(built.sampler, int(spp)), seed=int(seed))
    return np.array(img, dtype=np.float32)[..., :3]
