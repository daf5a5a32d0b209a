"""pycolmap incremental SfM on a dataset's views: SIFT extraction (one shared camera per
spec camera, COLMAP's SIMPLE_RADIAL model initialised from its default focal guess: no truth
intrinsics), exhaustive matching, incremental mapping. CPU only.

Reproducible: every stage runs on one thread and every COLMAP random generator (the global PRNG,
geometric verification's RANSAC, the mapper, the triangulator) is seeded with :data:`SEED`, so
two runs on the same dataset give the same model bit for bit (with threads, the order in which
matches and bundle-adjustment residuals are accumulated varied the max rotation error by ~1e-3
deg from run to run).

Raw output: ``colmap/database.db`` and the largest model ``colmap/sparse/`` (COLMAP binary).
Scores (recon_eval.metrics.poses): APE after Sim(3) Umeyama alignment on the camera centres (rotation
error per camera, translation error in metres), registration ratio (an unregistered view is a
failure with error inf, never dropped), and the sparse cloud mapped by the same Sim(3) into the
world frame and scored against the scene meshes (point-to-triangle, Chamfer and the fraction
within TAU_M). :func:`score_model` scores any COLMAP model so (an external method's too,
:mod:`recon_eval.runners.external`).
"""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.align import Alignment
from recon_eval.metrics.pointcloud import chamfer, tanks_and_temples
from recon_eval.metrics.poses import Poses, ape, registration_ratio
from recon_eval.readers.colmap_binary import read_colmap_binary
from recon_eval.readers.colmap_text import read_colmap_text
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.tasks.headlines import poses_headline

#: Distance threshold of the sparse-cloud accuracy, metres (Tanks-and-Temples-style precision).
TAU_M = 0.01
#: SIFT features per image (COLMAP's default is 8192; the library scenes are small images).
MAX_FEATURES = 4096
#: Seed of every COLMAP random generator; threads of every stage (both fixed: reproducible runs).
SEED = 0
THREADS = 1


def mapping_options(pycolmap):
    """COLMAP's incremental pipeline options, defaults but for :data:`THREADS` and :data:`SEED`."""
    o = pycolmap.IncrementalPipelineOptions()
    o.num_threads = THREADS
    o.random_seed = SEED
    o.mapper.num_threads = THREADS
    o.mapper.random_seed = SEED
    o.triangulation.random_seed = SEED
    return o


def incremental(ds, out_dir, options) -> RunOutput:
    import pycolmap  # optional (a dev dependency): only this method needs it

    if len(ds.views) < 3:
        raise NotApplicable(f"{ds.root}: SfM needs at least 3 views, the dataset has {len(ds.views)}")
    work = out_path(out_dir, "colmap/images")
    shutil.rmtree(work.parent, ignore_errors=True)
    work.mkdir(parents=True)
    for v in ds.views:
        shutil.copy(ds.image_path(v), work / f"{v}.png")
    db = work.parent / "database.db"
    pycolmap.set_random_seed(SEED)
    ext = pycolmap.FeatureExtractionOptions()
    ext.sift.max_num_features = MAX_FEATURES
    ext.num_threads = THREADS
    pycolmap.extract_features(db, work, camera_mode=pycolmap.CameraMode.SINGLE, extraction_options=ext,
                              device=pycolmap.Device.cpu)
    match = pycolmap.FeatureMatchingOptions()
    match.num_threads = THREADS
    verify = pycolmap.TwoViewGeometryOptions()
    verify.ransac.random_seed = SEED
    verify.ransac.num_threads = THREADS
    pycolmap.match_exhaustive(db, matching_options=match, verification_options=verify, device=pycolmap.Device.cpu)
    sparse = work.parent / "sparse_all"
    recs = pycolmap.incremental_mapping(db, work, sparse, options=mapping_options(pycolmap))
    out = RunOutput()
    out.notes.update({"seed": SEED, "threads": THREADS})
    if not recs:
        out.metrics.update({"registration_ratio": 0.0, "max_rot_err_deg": float("inf")})
        out.notes["failed"] = "no reconstruction"
        return out
    best = max(recs.values(), key=lambda r: r.num_reg_images())
    model = work.parent / "sparse"
    model.mkdir(exist_ok=True)
    best.write_binary(str(model))
    out.raw_files += ["colmap/database.db", "colmap/sparse/cameras.bin", "colmap/sparse/images.bin",
                      "colmap/sparse/points3D.bin"]
    shutil.rmtree(sparse, ignore_errors=True)
    shutil.rmtree(work, ignore_errors=True)  # the copies of the images
    return score_model(ds, model, out, n_registered=best.num_reg_images(), n_points=best.num_points3D())


def score_model(ds, model_dir, out: RunOutput, *, n_registered: int | None = None,
                n_points: int | None = None) -> RunOutput:
    """Score the COLMAP model in ``model_dir`` (binary, else text; image names ``<view>.<ext>``)
    against the dataset into ``out`` (module docstring). ``n_registered`` / ``n_points``: the
    mapper's own counts (default: the model's images and points)."""
    d = Path(model_dir)
    est_model = read_colmap_binary(d) if (d / "images.bin").is_file() else read_colmap_text(d)  # what was written
    est = est_model.poses
    names = tuple(n.rsplit(".", 1)[0] for n in est.names)
    est = Poses(names, est.R_cam_from_world, est.t_cam_from_world)
    gt = ds.poses
    n_reg = len(names) if n_registered is None else n_registered
    if n_reg < 3:  # Sim(3) needs 3 centres: a failed run, scored as such, not an input error
        out.metrics.update({"registration_ratio": registration_ratio(est, gt), "max_rot_err_deg": float("inf")})
        out.notes["failed"] = f"largest model registers {n_reg} images (< 3 for Sim(3))"
        return out
    a = ape(est, gt, alignment=Alignment.SIM3)
    out.results["ape_sim3"] = a
    pts = np.asarray(est_model.points_world, float).reshape(-1, 3)
    out.metrics.update(poses_headline(a, "sim3"))  # the names of ``recon-eval poses --json``
    out.metrics["n_points3d"] = int(len(pts) if n_points is None else n_points)
    if len(pts):
        pw = a.tgt_from_src.apply(pts)
        V, F = ds.mesh()
        tt = tanks_and_temples(pw, V, TAU_M, gt_mesh=(V, F), downsample=False)
        ch = chamfer(pw, V, gt_mesh=(V, F))
        out.results["sparse_cloud"] = {"tanks_and_temples_precision_at_tau": tt.precision, "tau_m": TAU_M,
                                       "chamfer": ch}
        out.metrics["cloud_precision_at_1cm"] = tt.precision
    return out
