"""The sequence truth as stored (docs/crossview.md, "Sequences"): the motion EXR of a frame pair,
the per-frame object poses and the index of ``sequence/``.

* ``sequence/motion/<a>/<b>.exr``, over a's pixels: ``u``, ``v`` (FLOAT, where a's surface point
  lands in b, OpenCV pixels of b), ``z`` (FLOAT, its depth along b's optical axis, metres),
  ``state`` (UINT, :data:`scenegen.dataset.crossview.STATE_NAMES`: 0 no surface, 1 visible,
  2 occluded, 3 out of frame), ``scene_flow.X/Y/Z`` (FLOAT): the point's 3D displacement
  P_b - P_a in the WORLD frame, metres. Optical flow = (u, v) - pixel of a; NaN where a saw
  nothing (or the point does not project into b's model).
* ``sequence/stereo_motion/<a>/<b>.exr`` (a, b: LEFT views of a stereo rig's frames), over the
  pixels of a's RECTIFIED left view (the ideal pinhole of ``crossview/stereo/<a>/``): ``u``, ``v``
  (FLOAT, where the surface point lands in b's rectified left view), ``z`` (FLOAT, its depth along
  b's rectified left axis, metres), ``disparity`` (FLOAT, ``f_b * B_b / z``, pixels of b's
  rectified pair; +inf where the point has no positive depth), ``state`` (UINT, in b's rectified
  left view) and ``state_right`` (UINT, in b's rectified right view), ``scene_flow.X/Y/Z`` (FLOAT,
  P_b - P_a, world frame, metres). NaN u, v, z where a saw nothing or the point does not project.
* ``sequence/objects.json``: per frame, every object's ``world_from_object`` (rigid, no scale),
  whether it exists (``present``) and its world-frame ``linear_velocity_mps`` (of its origin) and
  ``angular_velocity_rad_s``.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from scenegen.dataset.crossview import VISIBLE, Correspondence

SEQUENCE_FORMAT = "scenegen-sequence"
SEQUENCE_FORMAT_VERSION = 1
SCENE_FLOW_FRAME = "world"
SCENE_FLOW_CHANNELS = ("scene_flow.X", "scene_flow.Y", "scene_flow.Z")


@dataclass(frozen=True, eq=False)
class MotionTruth:
    """Where the surface points of frame a's pixels are at frame b (arrays over a's pixels)."""

    correspondence: Correspondence  # uv, z in b and state at b
    scene_flow: np.ndarray  # (H, W, 3) float64 world metres, P_b - P_a (NaN: no surface)

    @property
    def flow(self) -> np.ndarray:
        """(H, W, 2) float64 optical flow (u_b - x_a, v_b - y_a), pixels; NaN where unknown."""
        H, W = self.correspondence.state.shape
        grid = np.stack(np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64)), -1)
        return self.correspondence.uv - grid

    @property
    def state(self) -> np.ndarray:
        return self.correspondence.state


def encode_motion_channels(m: MotionTruth) -> dict[str, np.ndarray]:
    c = m.correspondence
    out = {"u": c.uv[..., 0].astype(np.float32), "v": c.uv[..., 1].astype(np.float32),
           "z": c.z.astype(np.float32), "state": c.state.astype(np.uint32)}
    for i, name in enumerate(SCENE_FLOW_CHANNELS):
        out[name] = m.scene_flow[..., i].astype(np.float32)
    return out


def decode_motion_channels(channels: Mapping[str, np.ndarray]) -> MotionTruth:
    """Inverse of :func:`encode_motion_channels` (float32 widened exactly); KeyError naming a
    missing channel."""
    missing = [k for k in ("u", "v", "z", "state") + SCENE_FLOW_CHANNELS if k not in channels]
    if missing:
        raise KeyError(f"motion channels {missing} missing; have {sorted(channels)}")
    uv = np.stack([channels["u"], channels["v"]], -1).astype(np.float64)
    c = Correspondence(uv, np.asarray(channels["z"], np.float64), np.asarray(channels["state"]).astype(np.uint8))
    sf = np.stack([channels[k] for k in SCENE_FLOW_CHANNELS], -1).astype(np.float64)
    return MotionTruth(c, sf)


@dataclass(frozen=True, eq=False)
class StereoMotionTruth:
    """Where the surface points of a's RECTIFIED left pixels are at b, in b's rectified pair
    (arrays over a's rectified left pixels): KITTI 2015 scene flow's flow and second disparity."""

    left: MotionTruth  # uv, z and state in b's rectified left view; world scene flow
    state_right: np.ndarray  # (H, W) uint8 state in b's rectified right view
    disparity: np.ndarray  # (H, W) float64 f_b B_b / z_b, pixels; +inf: no positive depth at b

    @property
    def flow(self) -> np.ndarray:
        """(H, W, 2) float64 optical flow of the rectified left view a -> b, pixels; NaN unknown."""
        return self.left.flow

    @property
    def state(self) -> np.ndarray:
        """(H, W) uint8 state in b's rectified left view."""
        return self.left.state

    @property
    def visible_both(self) -> np.ndarray:
        """(H, W) bool: b's rectified left AND right views see the moved point."""
        return (self.left.state == VISIBLE) & (self.state_right == VISIBLE)


STEREO_MOTION_CHANNELS = ("disparity", "state_right")


def encode_stereo_motion_channels(m: StereoMotionTruth) -> dict[str, np.ndarray]:
    out = encode_motion_channels(m.left)
    out.update({"disparity": m.disparity.astype(np.float32), "state_right": m.state_right.astype(np.uint32)})
    return out


def decode_stereo_motion_channels(channels: Mapping[str, np.ndarray]) -> StereoMotionTruth:
    """Inverse of :func:`encode_stereo_motion_channels`; KeyError naming a missing channel."""
    missing = [k for k in STEREO_MOTION_CHANNELS if k not in channels]
    if missing:
        raise KeyError(f"stereo motion channels {missing} missing; have {sorted(channels)}")
    return StereoMotionTruth(decode_motion_channels(channels), np.asarray(channels["state_right"]).astype(np.uint8),
                             np.asarray(channels["disparity"], np.float64))


def objects_document(frames) -> dict:
    """``sequence/objects.json`` from [(view-independent frame index, time_s, {name: (object_id,
    scenegen.spec.timeline.ObjectState)})]."""
    out = []
    for k, t, states in frames:
        objs = {}
        for name, (oid, st) in states.items():
            m = st.motion
            objs[name] = {"object_id": int(oid), "present": bool(st.present),
                          "world_from_object": m.world_from_frame.to_dict(),
                          "linear_velocity_mps": m.linear_velocity_mps.tolist(),
                          "angular_velocity_rad_s": m.angular_velocity_rad_s.tolist()}
        out.append({"index": int(k), "time_s": float(t), "objects": objs})
    return {"format": SEQUENCE_FORMAT + "-objects", "format_version": SEQUENCE_FORMAT_VERSION,
            "pose": "world_from_object: x_world = R x_object + t (metres; the object's scale acts "
                    "in the object frame); velocities in the world frame",
            "frames": out}
