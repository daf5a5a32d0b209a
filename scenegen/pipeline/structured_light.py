"""Views lit by a projector (structured light): a camera view whose rig holds a projector is
rendered once per pattern of the projector's sequence (docs/dataset_format.md, "Structured
light"). Pattern ``k``'s image goes through the camera's imaging chain like any image (its
temporal noise seeded per pattern), ``images/<view>.png`` and its linear EXR are pattern 0's,
and the view's projector truth is cast from its stored truth points
(:func:`scenegen.crossview.projector.projector_truth`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.crossview.projector import projector_truth
from scenegen.dataset.codecs import encode_json
from scenegen.dataset.codecs.exr import encode_exr, pack_channels
from scenegen.dataset.codecs.png import encode_png
from scenegen.dataset.layout import (pattern_image_path, pattern_linear_path, pattern_sequence_path,
                                     projector_truth_path)
from scenegen.dataset.structured_light import PATTERNS_FORMAT, encode_projector_truth
from scenegen.dataset.truth import LINEAR_CHANNELS, TruthKind
from scenegen.geometry.color import srgb_image
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.seeds import hashed_seed32
from scenegen.imaging import apply_chain
from scenegen.imaging.projector_sequences import frame_entry
from scenegen.imaging.seeds import frame_seed
from scenegen.spec.sensors import LIGHT, SENSOR_KINDS


@dataclass(frozen=True)
class LitView:
    """A view's projector: its rig member, its spec, its pose and its patterns."""

    member: object  # scenegen.spec.model.RigMember
    spec: object  # scenegen.spec.sensors.projector.ProjectorSpec
    projector_from_world: Rigid3
    sequence: object  # scenegen.imaging.patterns.PatternSequence


def lit_view(spec, view) -> LitView | None:
    """The projector lighting a camera view (its rig's one light member), else None."""
    if view.rig is None:
        return None
    rig = spec.rigs[view.rig]
    lights = [mb for mb in rig.members if SENSOR_KINDS[mb.kind].produces == LIGHT]
    if not lights:
        return None
    if len(lights) > 1:
        raise ValueError(f"rig {rig.name!r} holds {len(lights)} projectors; a view is lit by at most one")
    member = lights[0]
    cam_member = next(mb for mb in rig.members if mb.name == view.rig_member)
    # projector_from_world = projector_from_rig @ rig_from_cam @ cam_from_world
    projector_from_world = member.rig_from_sensor.inverse() @ cam_member.rig_from_sensor @ view.cam_from_world
    p = SENSOR_KINDS[member.kind].sensors_of(spec)[member.sensor]
    return LitView(member, p, projector_from_world, p.pattern_sequence())


def render_patterns(built, view, lit: LitView, *, spp: int, seed: int, time_s, count: int | None = None
                    ) -> list[np.ndarray]:
    """Linear float32 (H, W, 3) renders of the view under each pattern (the first ``count``;
    None: all); pattern k's sampler seed is hashed from the view's seed and k."""
    return [built.render_pattern(view.camera, view.cam_from_world, lit.member.sensor, lit.projector_from_world,
                                 values, spp=spp, seed=hashed_seed32(seed, k), motion=view.motion,
                                 light_scales=view.light_scales, time_s=time_s)
            for k, values in enumerate(lit.sequence.images[:count])]


def pattern_files(spec, built, index: int, view, lit: LitView, linears, image0, truth, visible) -> dict[str, bytes]:
    """The pattern images (pattern 0's is ``image0``, the view's image), their linear EXRs, the
    sequence document and the projector truth of a view; ``truth`` as stored, ``visible`` the
    visibility cast at the view's time."""
    cam = built.cameras[view.camera]
    params = spec.cameras[view.camera].imaging
    files = {}
    entries = []
    for k, (frame, linear) in enumerate(zip(lit.sequence.frames, linears)):
        if k == 0:
            image = image0
        elif params is None:
            image = srgb_image(linear, spec.render.bit_depth)
        else:  # the chain's temporal noise drawn anew for each pattern
            image = apply_chain(linear, params, cam, hashed_seed32(frame_seed(spec.seed, index), k)).image
        files[pattern_image_path(view.name, k)] = encode_png(image)
        entry = {"index": k, **frame_entry(frame), "image": pattern_image_path(view.name, k)}
        if lit.spec.linear_patterns:
            entry["linear"] = pattern_linear_path(view.name, k)
            files[entry["linear"]] = encode_exr(pack_channels("", linear.astype(np.float32), LINEAR_CHANNELS))
        entries.append(entry)
    p = lit.spec
    world_from_cam = view.cam_from_world.inverse()
    doc = {"format": PATTERNS_FORMAT, "view": view.name,
           "projector": {"name": lit.member.sensor, "member": lit.member.name, "camera": p.to_camera().to_dict(),
                         "projector_from_world": lit.projector_from_world.matrix.tolist(),
                         "cam_from_projector": (view.cam_from_world @ lit.projector_from_world.inverse()).matrix.tolist(),
                         "intensity_w_sr": list(p.intensity_w_sr), "gamma": p.gamma, "black_level": p.black_level,
                         "falloff": p.falloff, "sequence": p.patterns},
           "patterns": entries}
    files[pattern_sequence_path(view.name)] = encode_json(doc)
    u, v = np.meshgrid(np.arange(cam.width + 1) - 0.5, np.arange(cam.height + 1) - 0.5)
    corners = built.surface_points(cam, view.cam_from_world, np.stack([u.ravel(), v.ravel()], axis=1),
                                   time_s=getattr(view, "time_s", None)).reshape(cam.height + 1, cam.width + 1, 3)
    t = projector_truth(truth[TruthKind.POINTS_WORLD], truth[TruthKind.NORMALS_WORLD], world_from_cam.t,
                        p.to_camera(), lit.projector_from_world, visible, corners)
    files[projector_truth_path(view.name)] = encode_projector_truth(t)
    return files
