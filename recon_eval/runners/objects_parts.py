"""Articulated objects by parts (the course's third method): each part of the articulated tree
is posed on its own, as a rigid object (the alignment method, :mod:`.objects_align`, on the
dataset's BOP export, where every part is a model), then the joints are recovered as the
relative rotations of child and parent part (:func:`recon_eval.metrics.objects_parts.
joint_rotation_errors`). Per image the best-scored estimate of each part is the part's pose.

Scores: BOP19 AR of the parts (the CSV), per-part rotation / translation / ADD errors and the
joint errors against the truth; the tree (child -> parent) comes from the dataset's object truth.
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.objects_bop import symmetry_transforms
from recon_eval.metrics.objects_parts import articulated_pose_errors, joint_rotation_errors
from recon_eval.runners import objects_align
from recon_eval.runners.objects_common import bop_export, score_bop_run


def best_per_part(rows) -> dict:
    """(scene_id, im_id) -> obj_id -> (R, t) of the highest-scored row."""
    best: dict = {}
    for scene_id, im_id, obj_id, score, R, t, _ in rows:
        cur = best.setdefault((scene_id, im_id), {}).get(obj_id)
        if cur is None or score > cur[0]:
            best[(scene_id, im_id)][obj_id] = (score, R, t)
    return {k: {o: (R, t) for o, (_, R, t) in v.items()} for k, v in best.items()}


def part_errors(bop, rows, parents: dict) -> dict:
    """Per image: :class:`ArticulatedPoseResult` of the best estimate of each part (obj_id) and
    the joint rotation errors for ``parents`` (child obj_id -> parent obj_id)."""
    est = best_per_part(rows)
    out = {}
    for key, gts in sorted(bop.gts.items()):
        gt = {g.obj_id: (g.R, g.t) for g in gts}
        e = est.get(key, {})
        syms = {o: symmetry_transforms(bop.models[o].info) for o in gt}
        r = articulated_pose_errors(e, gt, {o: bop.models[o].vertices for o in gt}, syms)
        joints = joint_rotation_errors(e, gt, {c: p for c, p in parents.items() if c in gt})
        out[f"scene{key[0]}_im{key[1]}"] = {"parts": r, "joint_rot_err_deg": joints,
                                            "max_joint_rot_err_deg": max(joints.values(), default=float("nan"))}
    return out


def tree(ds) -> dict:
    """child model id -> parent model id, from the object truth of the dataset's first view."""
    objs = ds.objects(ds.views[0]) if hasattr(ds, "objects") else None
    if objs is None:
        raise NotApplicable(f"{ds.root}: no object truth (truth: {{objects: true}}): the part tree is unknown")
    by_name = {o.name: o for o in objs.objects}
    return {o.model_id: by_name[o.parent].model_id for o in objs.objects if o.parent in by_name}


def run(ds, out_dir, options: dict):
    parents = tree(ds)
    if not parents:
        raise NotApplicable(f"{ds.root}: no articulated object (no part has a parent)")
    bop = bop_export(ds)
    rows, notes = objects_align.estimate(bop, int(options.get("trials", objects_align.TRIALS)),
                                         int(options.get("ransac_iterations", objects_align.RANSAC_ITERATIONS)))
    out = score_bop_run(bop, out_dir, rows, dict(notes, parents={str(c): p for c, p in parents.items()}))
    per_image = part_errors(bop, rows, parents)
    out.results["parts"] = per_image
    joints = [v for r in per_image.values() for v in r["joint_rot_err_deg"].values()]
    out.metrics["median_joint_rot_err_deg"] = float(np.median(joints)) if joints else float("nan")
    return out
