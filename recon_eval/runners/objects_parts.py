"""Articulated objects by parts (the course's third method): each part of the articulated tree
is posed on its own, as a rigid object (the alignment method, :mod:`.objects_align`, on the
dataset's BOP export, where every part is a model), then the joints are recovered from the
relative rotation of child and parent part: its angle against the truth's
(:func:`~recon_eval.metrics.objects_parts.joint_rotation_errors`, any joint) and, for a revolute
joint of the object truth, the joint angle itself (its twist about the joint axis,
:func:`~recon_eval.metrics.objects_parts.recovered_joint_angle_rad`). Per image the best-scored estimate of each part is the part's pose.

Scores: BOP19 AR of the parts (the CSV), per-part rotation / translation / ADD errors and the
joint errors against the truth; the tree (child -> parent) comes from the dataset's object truth.
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.objects_bop import symmetry_transforms
from recon_eval.metrics.objects_parts import articulated_pose_errors, joint_rotation_errors, recovered_joint_angle_rad
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


def joint_angles(est: dict, gt: dict, parents: dict, joints: dict) -> dict:
    """child obj_id -> {truth_deg, recovered_deg, err_deg} of each revolute joint in ``joints``
    (child obj_id -> the object truth's joint: type, axis, value) whose parts are both estimated
    (err inf otherwise)."""
    out = {}
    for child, j in joints.items():
        parent = parents.get(child)
        if j is None or j.get("type") != "revolute" or parent not in gt or child not in gt:
            continue
        truth = float(np.degrees(j["value"]))
        if child not in est or parent not in est:
            out[child] = {"truth_deg": truth, "recovered_deg": float("nan"), "err_deg": float("inf")}
            continue
        rec = float(np.degrees(recovered_joint_angle_rad(est[parent][0], est[child][0], gt[parent][0], gt[child][0],
                                                         j["axis"], j["value"])))
        out[child] = {"truth_deg": truth, "recovered_deg": rec,
                      "err_deg": float(abs((rec - truth + 180.0) % 360.0 - 180.0))}
    return out


def part_errors(bop, rows, parents: dict, joints: dict | None = None) -> dict:
    """Per image: :class:`ArticulatedPoseResult` of the best estimate of each part (obj_id), the
    joint rotation errors for ``parents`` (child obj_id -> parent obj_id) and, with ``joints``
    ((scene_id, im_id) -> child obj_id -> joint truth), the recovered revolute joint angles."""
    est = best_per_part(rows)
    out = {}
    for key, gts in sorted(bop.gts.items()):
        gt = {g.obj_id: (g.R, g.t) for g in gts}
        e = est.get(key, {})
        syms = {o: symmetry_transforms(bop.models[o].info) for o in gt}
        r = articulated_pose_errors(e, gt, {o: bop.models[o].vertices for o in gt}, syms)
        rel = joint_rotation_errors(e, gt, {c: p for c, p in parents.items() if c in gt})
        rec = joint_angles(e, gt, parents, (joints or {}).get(key, {}))
        out[f"scene{key[0]}_im{key[1]}"] = {"parts": r, "joint_rot_err_deg": rel, "joint_angles": rec,
                                            "max_joint_rot_err_deg": max(rel.values(), default=float("nan"))}
    return out


def tree(ds) -> tuple[dict, dict]:
    """(child model id -> parent model id, (0, im_id) -> child model id -> joint truth) from the
    dataset's object truth; BOP's im_id is the view's position (scenegen's BOP export)."""
    objs = ds.object_truth(ds.views[0])
    if objs is None:
        raise NotApplicable(f"{ds.root}: no object truth (truth: {{objects: true}}): the part tree is unknown")
    by_name = {o.name: o for o in objs.objects}
    parents = {o.model_id: by_name[o.parent].model_id for o in objs.objects if o.parent in by_name}
    joints = {}
    for im_id, view in enumerate(ds.views):
        v = ds.object_truth(view)
        joints[(0, im_id)] = {o.model_id: o.joint for o in (v.objects if v else ()) if o.joint is not None}
    return parents, joints


def run(ds, out_dir, options: dict):
    parents, joints = tree(ds)
    if not parents:
        raise NotApplicable(f"{ds.root}: no articulated object (no part has a parent)")
    bop = bop_export(ds)
    rows, notes = objects_align.estimate(bop, int(options.get("trials", objects_align.TRIALS)),
                                         int(options.get("ransac_iterations", objects_align.RANSAC_ITERATIONS)))
    out = score_bop_run(bop, out_dir, rows, dict(notes, parents={str(c): p for c, p in parents.items()}))
    per_image = part_errors(bop, rows, parents, joints)
    out.results["parts"] = per_image
    rel = [v for r in per_image.values() for v in r["joint_rot_err_deg"].values()]
    ang = [j["err_deg"] for r in per_image.values() for j in r["joint_angles"].values()]
    out.metrics["median_joint_rot_err_deg"] = float(np.median(rel)) if rel else float("nan")
    out.metrics["median_joint_angle_err_deg"] = float(np.median(ang)) if ang else float("nan")
    return out
