"""The rectified stereo frames of the cross-view stage: both sides rendered as the same ideal
pinhole (no resampling), exact disparity from their truth, correspondences with visibility,
KITTI PNGs, rectification maps and calib.json (docs/crossview.md, "Rectified stereo").

Rectified views are ideal pinholes: no lens blur, motion or chromatic aberration, the clean
sRGB encoding, both sides under the left view's lighting (its view set's ``lights``).
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset.codecs import (
    encode_exr,
    encode_json,
    encode_kitti_disparity,
    encode_pfm,
    encode_png,
    pack_channels,
)
from scenegen.dataset.crossview import VISIBLE, encode_correspondence_channels, encode_rectification_map
from scenegen.dataset.layout import STEREO_SIDES, stereo_dir, stereo_path
from scenegen.dataset.truth import LINEAR_CHANNELS, TruthKind, truth_id_channels
from scenegen.geometry.color import srgb_image
from scenegen.geometry.rectify import disparity_from_depth, rectification_map, rectify
from scenegen.geometry.seeds import hashed_seed32
from scenegen.geometry.twoview import TwoView
from scenegen.pipeline.active_stereo import write_ir_frame
from scenegen.pipeline.view import correspond_points


def write_stereo_frame(ctx, left: str, right: str, *, spp: int, seed: int) -> dict:
    """Write one rectified frame through ``ctx`` (the stage's context); returns its index entry."""
    cam_l, pose_l = ctx.camera(left)
    cam_r, pose_r = ctx.camera(right)
    rect = rectify(cam_l, pose_l, cam_r, pose_r)
    rc = rect.camera
    built = ctx.built
    view_l = ctx.views[left]
    time_s = ctx.time_s(left)  # a sequence's frame: its objects at its time (both members share it)
    truths, passive, full, states = {}, {}, {}, {}
    for side, pose in zip(STEREO_SIDES, (rect.cam_left_from_world, rect.cam_right_from_world)):
        lin = built.render_ideal(view_l.camera, rc, pose, spp=spp, seed=hashed_seed32(seed, left, side),
                                 light_scales=view_l.light_scales, time_s=time_s)  # both: the left view's lighting
        ctx.write(stereo_path(left, "image", side), encode_png(srgb_image(lin, ctx.spec.render.bit_depth)))
        ctx.write(stereo_path(left, "linear", side), encode_exr(pack_channels("", lin, LINEAR_CHANNELS)))
        t = built.truth(rc, pose, time_s=time_s)
        passive[side], full[side] = lin, t
        ctx.write(stereo_path(left, "ids", side), encode_exr(truth_id_channels(t)))
        truths[side] = (np.where(t[TruthKind.VALID][..., None], t[TruthKind.POINTS_WORLD], np.nan),
                        t[TruthKind.DEPTH_Z])
    for side, other_pose in zip(STEREO_SIDES, (rect.cam_right_from_world, rect.cam_left_from_world)):
        pts, depth = truths[side]
        d = disparity_from_depth(depth, rect.f, rect.baseline_m)
        c = correspond_points(built, pts, rc, other_pose, time_s)
        states[side] = c.state
        ctx.write(stereo_path(left, "disparity_pfm", side), encode_pfm(d))
        ctx.write(stereo_path(left, "disparity_occ", side), encode_kitti_disparity(d, np.isfinite(d)))
        ctx.write(stereo_path(left, "disparity_noc", side), encode_kitti_disparity(d, c.state == VISIBLE))
        ctx.write(stereo_path(left, "correspondence", side), encode_exr(encode_correspondence_channels(c)))
    for side, raw, R in zip(STEREO_SIDES, (cam_l, cam_r), (rect.R1, rect.R2)):
        mp = rectification_map(raw, R, rc)
        ctx.write(stereo_path(left, "map", side), encode_exr(encode_rectification_map(mp)))
    write_ir_frame(ctx, left, rect, passive, full, states, spp=spp, seed=seed, time_s=time_s)  # with a projector
    calib = rect.to_dict()
    calib.update({"left_view": left, "right_view": right,
                  "raw_left": {"camera": cam_l.to_dict(), "cam_from_world": pose_l.to_dict()},
                  "raw_right": {"camera": cam_r.to_dict(), "cam_from_world": pose_r.to_dict()},
                  "twoview_raw": TwoView.of(cam_l, pose_l, cam_r, pose_r).to_dict()})
    ctx.write(stereo_path(left, "calib"), encode_json(calib))
    return {"left_view": left, "right_view": right, "dir": stereo_dir(left)}
