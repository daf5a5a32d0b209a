"""Active IR stereo (RealSense-like): a stereo frame whose rig holds a projector (docs/crossview.md,
"Active IR stereo"; docs/dataset_format.md). Beside the passive rectified pair the frame gets:

* ``ir_<side>.png``: the rectified side lit by the projector's first pattern (a random dot
  pattern for an IR emitter) on top of the scene's lights (the ambient), as a monochrome sensor
  records it; ``ir_off_<side>.png``: the same with the projector off (the passive render).
* ``ir_invalid_<side>.png``: why a pixel's disparity cannot be measured
  (:mod:`scenegen.dataset.ir_stereo`).

Monochrome: an IR camera has no colour filter; the scene's RGB radiance is averaged over the three
channels (its stand-in for the IR band) and replicated, put through the camera's imaging chain
(shot, read and quantisation noise; docs/image_formation.md), or the clean encoding without one,
and one channel of the result kept (one sensor value per pixel: the noise of one pixel, not an
average of three). The disparity truth is the frame's own (``disp_<side>.pfm`` = f B / z).
"""
from __future__ import annotations

import numpy as np

from scenegen.crossview.projector import projector_lit
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.ir_stereo import encode_invalid, invalid_mask
from scenegen.dataset.layout import STEREO_SIDES, stereo_path
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.color import srgb_image
from scenegen.geometry.seeds import hashed_seed32
from scenegen.imaging import apply_chain
from scenegen.pipeline.structured_light import lit_view
from scenegen.spec.model.crossview import CrossviewSpec


def ir_image(linear, params, camera, seed: int, bit_depth: int) -> np.ndarray:
    """(H, W) uint8/uint16 monochrome image of a linear (H, W, 3) render (module docstring)."""
    grey = np.repeat(np.asarray(linear, np.float64).mean(axis=-1, keepdims=True), 3, axis=-1)
    img = srgb_image(grey, bit_depth) if params is None else apply_chain(grey.astype(np.float32), params, camera,
                                                                         seed).image
    return np.ascontiguousarray(img[..., 1])


def write_ir_frame(ctx, left: str, rect, passive, truths, states, *, spp: int, seed: int, time_s) -> bool:
    """The active IR files of the frame of ``left`` when its rig holds a projector; ``rect`` the
    rectification, ``passive`` {side: linear render, projector off}, ``truths`` {side: truth
    dict}, ``states`` {side: correspondence state in the other side}. False without a projector."""
    view_l = ctx.views[left]
    lit = lit_view(ctx.spec, view_l)
    if lit is None:
        return False
    rc, built = rect.camera, ctx.built
    params = ctx.spec.cameras[view_l.camera].imaging
    bits = ctx.spec.render.bit_depth
    projector = lit.spec.to_camera()
    visible = lambda c, p: built.visible_from(c, p, time_s=time_s)  # noqa: E731
    for side, pose in zip(STEREO_SIDES, (rect.cam_left_from_world, rect.cam_right_from_world)):
        lin = built.render_ideal_pattern(view_l.camera, rc, pose, lit.member.sensor, lit.projector_from_world,
                                         lit.sequence.images[0], spp=spp, seed=hashed_seed32(seed, left, side, "ir"),
                                         light_scales=view_l.light_scales, time_s=time_s)
        for key, linear in (("ir", lin), ("ir_off", passive[side])):
            img = ir_image(linear, params, rc, hashed_seed32(seed, left, side, key), bits)
            ctx.write(stereo_path(left, key, side), encode_png(img))
        t = truths[side]
        points = np.where(t[TruthKind.VALID][..., None], t[TruthKind.POINTS_WORLD], np.nan)
        lit_px = projector_lit(points, t[TruthKind.NORMALS_WORLD], pose.inverse().t, projector,
                               lit.projector_from_world, visible)[1]
        depth = np.where(t[TruthKind.VALID], t[TruthKind.DEPTH_Z], np.nan)
        mask = invalid_mask(depth, lit_px, states[side], (ctx.spec.crossview or CrossviewSpec()).ir_depth_range_m)
        ctx.write(stereo_path(left, "ir_invalid", side), encode_invalid(mask))
    return True
