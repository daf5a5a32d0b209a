"""A turntable scan (``scenes/sl_desktop_scanner.yaml``): one Gray-code scan per turntable step
(:mod:`recon_eval.runners.structured_light`), each step's cloud registered with the known
turntable motion, merged, and scored against the object's truth mesh.

Registration: a step ``k``'s points move with the object, so ``world_from_object(0) @
object_from_world(k)`` carries them to where the object stood at step 0 (the per-frame object
poses of ``sequence/objects.json``: the turntable's revolute joint on the clock). The merged
cloud is cropped to the object's truth bounding box (at step 0) grown by ``crop_margin_m``, as
Tanks and Temples crops to a given volume (the turntable and the table are not the object).

Scores (:mod:`recon_eval.metrics.pointcloud`): Tanks and Temples precision / recall / F-score at
``tau_m`` (1 mm), distances from the cloud to the truth mesh surface and from truth samples of the
surface (uniform, seeded, one per (tau / 4)^2 of area) to the cloud; DTU accuracy, completeness
and overall; Chamfer. The unseen underside counts against recall, as it would for a real scan.

Raw output: ``step_<k>.ply`` (each step's cloud, registered) and ``merged.ply``; read back and scored.
"""
from __future__ import annotations

import numpy as np
import trimesh

from recon_eval.errors import NotApplicable
from recon_eval.metrics.pointcloud import chamfer, dtu, tanks_and_temples
from recon_eval.readers.ply import read_geometry, write_point_cloud_ply
from recon_eval.readers.structured_light import projector_views
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.runners.structured_light import decode_gray_view, triangulate_view

#: Seed of the truth surface samples.
SAMPLE_SEED = 27


def _moving_object(ds) -> str:
    ids = ds.read(ds.dataset.sequence.moving_object_ids)
    names = [o["name"] for o in ds.objects if int(o.get("object_id", 0)) in ids and o["name"] in ds.dataset.mesh_names]
    if not names:
        raise NotApplicable(f"{ds.root}: no moving object with a mesh (a turntable scan needs one)")
    return names[0]


def run(ds, out_dir, options) -> RunOutput:
    tau_m = float(options.get("tau_m", 0.001))
    margin = float(options.get("crop_margin_m", 0.002))
    if ds.read(lambda: ds.dataset.sequence.index) is None:
        raise NotApplicable(f"{ds.root}: not a sequence (a turntable scan needs the object's pose per step)")
    name = str(options.get("object") or _moving_object(ds))
    views = projector_views(ds.root, source=str(options.get("source", "png")))
    seq = ds.dataset.sequence
    world0_from_object = ds.read(seq.object_poses, 0)[name][0]
    mesh = ds.read(ds.dataset.mesh, name)
    # the stored mesh is where the object stands at frame 0 (checked against the truth points)
    V, F = np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)
    lo, hi = V.min(axis=0) - margin, V.max(axis=0) + margin
    raw, steps, per_step = [], [], {}
    for pv in views:
        codes = decode_gray_view(pv, float(options.get("threshold", 0.1)), float(options.get("min_contrast", 0.005)))
        pts, _ = triangulate_view(pv, codes, "plane")
        p = pts[np.all(np.isfinite(pts), axis=2)]
        world_from_object = ds.read(seq.object_poses, pv.frame_index)[name][0]
        p = (world0_from_object @ world_from_object.inverse()).apply(p)
        p = p[np.all((p >= lo) & (p <= hi), axis=1)]
        write_point_cloud_ply(out_path(out_dir, f"step_{pv.frame_index}.ply"), p)
        raw.append(f"step_{pv.frame_index}.ply")
        steps.append(read_geometry(out_path(out_dir, f"step_{pv.frame_index}.ply")).vertices)
        per_step[pv.view] = len(p)
    if not steps:
        raise NotApplicable(f"{ds.root}: no projector-lit step")
    write_point_cloud_ply(out_path(out_dir, "merged.ply"), np.concatenate(steps))
    raw.append("merged.ply")
    merged = read_geometry(out_path(out_dir, "merged.ply")).vertices
    tm = trimesh.Trimesh(V, F, process=False)
    n = int(np.ceil(tm.area / (tau_m / 4) ** 2))
    gt, _ = trimesh.sample.sample_surface(tm, n, seed=SAMPLE_SEED)
    gt = np.asarray(gt, np.float64)
    results = {"tnt": tanks_and_temples(merged, gt, tau_m, gt_mesh=(V, F)),
               "dtu": dtu(merged, gt, gt_mesh=(V, F)), "chamfer": chamfer(merged, gt, gt_mesh=(V, F))}
    for k, s in enumerate(steps):
        results[f"step_{k}.tnt"] = tanks_and_temples(s, gt, tau_m, gt_mesh=(V, F))
    t, d = results["tnt"], results["dtu"]
    metrics = {"fscore": t.fscore, "precision": t.precision, "recall": t.recall,
               "dtu_overall_mm": 1e3 * d.overall_mean_m, "dtu_acc_mm": 1e3 * d.acc_mean_m,
               "dtu_comp_mm": 1e3 * d.comp_mean_m}
    notes = {"object": name, "tau_m": tau_m, "crop_margin_m": margin, "points_per_step": per_step,
             "gt_samples": n, "views": [pv.view for pv in views]}
    return RunOutput(results, metrics, raw, notes)
