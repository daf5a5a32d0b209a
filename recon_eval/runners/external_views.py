"""Kinds of a user's command (:mod:`recon_eval.runners.external`, ``KINDS``) scored as the built-in
keypoint and absolute-pose methods (docs/ci.md, "Your own estimator"):

* ``features``: once per dataset: ``{images}`` a folder of ``<view>.png`` and ``{pairs}`` a text
  file of the cross-view pairs (``view_i view_j`` per line) -> ``{out}`` a folder in recon_eval's
  feature format (``keypoints/<view>.txt``, ``matches/<view_i>__<view_j>.txt``, docs/features.md);
  scored as ``opencv-features-*`` and ``recon-eval features``.
* ``pnp``: per view (OpenCV / pinhole cameras): ``{image}``, ``{points}`` (an (N, 5) ``.npy`` of
  ``u v X Y Z``: the ``points`` input of the built-in PnP methods, noisy truth pixels with 30 %
  outliers, world metres) and ``{k}`` / ``{dist}`` (3x3 text, OpenCV's distortion row) ->
  ``{out}`` cam_from_world as 3x4 text ``[R | t]``; scored as the built-in PnP methods' ``points``
  (``points.median_rot_err_deg``, ...).
* ``normals``: per photometric stereo set under distant lights: ``{images}`` its images in order,
  ``{lights}`` (``light_directions.txt``: one row ``x y z`` per image, DiLiGenT's axes: x right,
  y up, z toward the camera), ``{intensities}`` (``light_intensities.txt``: ``r g b`` per image)
  and ``{mask}`` (PNG, 255 on the objects) -> ``{out}`` an (H, W, 3) ``.npy`` normal map in
  DiLiGenT's axes; DiLiGenT's angular errors over all objects and per object, as ``woodham-ps``
  and ``recon-eval normals`` (``all.mean_ae_deg``, ``<object>.median_ae_deg``, ``.within_10deg``).
* ``cloud``: once: ``{images}`` a folder of ``<view>.png`` (the calibrated cameras are the
  dataset's ``cameras.json``, ``{dataset}``) -> ``{out}`` a ``.ply`` point cloud or mesh (its
  vertices are scored); against the scene's meshes as ``recon-eval cloud`` at its defaults:
  Tanks and Temples at 1 cm (a 200 000-point surface sample, seed 0, tau/2 voxel downsampling) and
  Chamfer-L1 (``tnt_precision_at_1cm``, ``tnt_recall_at_1cm``, ``tnt_fscore_at_1cm``,
  ``chamfer_l1_m``).
* ``triangulation``: per triangulation task of ``opencv-triangulate`` (its pixel noises 0 and
  1 px): ``{task}`` the task folder (``recon-eval triangulation-task``'s layout: ``<pair>/P1.txt``,
  ``P2.txt``, ``observations.txt``) -> ``{out}`` a folder of ``<pair>.txt`` (``X Y Z`` per
  observation row, world metres); scored as ``opencv-triangulate`` (``sigma0.median_err_m``, ...).
* ``dlt``: per view and input of ``dlt-linear`` (``targets``: detected board corners; ``points``:
  noisy truth points): ``{points}`` an (N, 5) ``.npy`` of ``u v X Y Z`` (undistorted pixels, world
  metres) -> ``{out}`` the camera matrix P (3x4 text); scored as ``dlt-linear``
  (``targets.median_fx_rel_err``, ``points.median_rot_err_deg``, ...).
"""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.distances import MeshSurface, sample_mesh_surface
from recon_eval.metrics.normals import normal_metrics
from recon_eval.metrics.pnp import pnp_errors
from recon_eval.metrics.pointcloud import chamfer, tanks_and_temples
from recon_eval.readers.features import read_feature_files
from recon_eval.readers.npy import read_npy
from recon_eval.readers.photometric import photometric_sets
from recon_eval.readers.ply import read_geometry
from recon_eval.readers.rows import read_projection_matrix
from recon_eval.runners import dlt as dlt_runner, pnp as pnp_runner, triangulate as triangulate_runner
from recon_eval.runners.common import RunOutput, crossview_pairs, out_path
from recon_eval.runners.external import failed_output, invoke
from recon_eval.tasks.feature_eval import DEFAULT_EPS_PX, evaluate_features, headline_metrics, results_dict
from recon_eval.tasks.headlines import CLOUD_TAU_M, cloud_headline, normals_headline
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.files import atomic_write_bytes
from scenegen.dataset.layout import check_view_name
from scenegen.geometry.camera import camera_model
from scenegen.geometry.conventions import DILIGENT_FROM_OPENCV_CAM

#: Truth surface samples of the cloud kind (``recon-eval cloud --gt-samples``' default).
CLOUD_GT_SAMPLES = 200_000


def features(ds, out_dir, options) -> RunOutput:
    """The ``features`` kind (module docstring)."""
    pairs = list(crossview_pairs(ds))
    views = list(dict.fromkeys(v for p in pairs for v in p))
    images, result = out_path(out_dir, "images/x").parent, Path(out_dir) / "features"
    shutil.rmtree(images, ignore_errors=True)
    shutil.rmtree(result, ignore_errors=True)
    images.mkdir(parents=True)
    result.mkdir()
    for v in views:
        shutil.copy(ds.image_path(v), images / f"{check_view_name(v)}.png")
    pairs_txt = out_path(out_dir, "pairs.txt")
    pairs_txt.write_text("".join(f"{i} {j}\n" for i, j in pairs))
    out = RunOutput()
    why = invoke(options, {"images": str(images.resolve()), "pairs": str(pairs_txt.resolve()),
                           "out": str(result.resolve()), "dataset": str(Path(ds.root).resolve())},
                 Path(out_dir) / "logs", "features", out)
    shutil.rmtree(images, ignore_errors=True)  # the copies of the images
    files = None
    if why is None:
        try:
            files = read_feature_files(result, views, pairs)
        except InputError as exc:  # unreadable files are the method's failure: scored with no keypoints
            failed_output(out, "features", str(exc))
    none = {v: np.zeros((0, 2)) for v in views}
    ev = evaluate_features(ds, none if files is None else files.keypoints, {} if files is None else files.matches,
                           pairs, DEFAULT_EPS_PX)
    out.results = results_dict(ev, files)
    out.metrics = headline_metrics(ev)
    if files is not None:
        out.raw_files += sorted(str(f.relative_to(out_dir)) for f in result.rglob("*") if f.is_file())
    return out


def pnp(ds, out_dir, options) -> RunOutput:
    """The ``pnp`` kind (module docstring)."""
    rng = np.random.default_rng(pnp_runner.SEED)  # the built-in methods' draws, view by view
    out, errs = RunOutput(), {"points": []}
    root = str(Path(ds.root).resolve())
    for v in ds.views:
        cam, pose = ds.camera(v)
        if camera_model(cam.model).opencv_fisheye:  # as the built-in methods: OpenCV's perspective models
            continue
        name = check_view_name(v)
        uv, X = pnp_runner.noisy_points(ds, v, cam, rng)
        d = Path(out_dir) / name
        d.mkdir(parents=True, exist_ok=True)
        K, D = cam.to_opencv()
        paths = {"points": d / "points.npy", "k": d / "K.txt", "dist": d / "dist.txt", "out": d / "pose.txt"}
        np.save(paths["points"], np.concatenate([uv, X], axis=1))
        np.savetxt(paths["k"], K, fmt="%.17g")
        np.savetxt(paths["dist"], np.reshape(D, (1, -1)), fmt="%.17g")
        paths["out"].unlink(missing_ok=True)
        values = {k: str(p.resolve()) for k, p in paths.items()}
        values.update(image=str(ds.image_path(v).resolve()), view=name, dataset=root)
        why = invoke(options, values, d, name, out)
        Rt = None
        if why is None and not paths["out"].is_file():
            failed_output(out, name, "wrote no pose.txt")
        elif why is None:
            try:
                Rt = read_npy_or_text(paths["out"])
                out.raw_files.append(f"{name}/pose.txt")
            except InputError as exc:
                failed_output(out, name, str(exc))
        if Rt is None:
            r = pnp_errors(np.full((3, 3), np.nan), np.full(3, np.nan), pose.R, pose.t)
        else:
            r = pnp_errors(Rt[:, :3], Rt[:, 3], pose.R, pose.t, cam=cam, points_world=X, pixels=uv)
        out.results[f"points.{v}"] = r
        errs["points"].append((r.rot_err_deg, r.trans_abs_err_m, r.failed, float("inf")))
    if not errs["points"]:
        raise NotApplicable(f"{ds.root}: no view with an OpenCV/pinhole camera")
    pnp_runner.headline(errs, out)
    return out


def read_npy_or_text(path: Path) -> np.ndarray:
    """A 3x4 ``[R | t]`` from a text file (whitespace between numbers) or a ``.npy``."""
    if path.suffix == ".npy":
        return read_npy(path, (3, 4))
    try:
        a = np.loadtxt(path, ndmin=2)
    except ValueError as exc:
        raise InputError(f"{path}: expected 3 rows of 4 numbers ([R | t], cam_from_world): {exc}") from None
    if a.shape != (3, 4):
        raise InputError(f"{path}: expected 3 rows of 4 numbers ([R | t], cam_from_world), got shape {a.shape}")
    return a


def normals(ds, out_dir, options) -> RunOutput:
    """The ``normals`` kind (module docstring)."""
    sets = [s for s in photometric_sets(ds.root) if np.isnan(s.positions_cam).all()]
    if not sets:
        raise NotApplicable(f"{ds.root}: no photometric stereo set under distant (directional) lights")
    out = RunOutput()
    root = str(Path(ds.root).resolve())
    for k, s in enumerate(sets):
        name = f"set{k}" if len(sets) > 1 else "ps"
        d = Path(out_dir) / name
        d.mkdir(parents=True, exist_ok=True)
        paths = {"lights": d / "light_directions.txt", "intensities": d / "light_intensities.txt",
                 "mask": d / "mask.png", "out": d / "normals.npy"}
        np.savetxt(paths["lights"], s.directions_cam @ DILIGENT_FROM_OPENCV_CAM.T, fmt="%.17g")
        np.savetxt(paths["intensities"], s.intensities, fmt="%.17g")
        atomic_write_bytes(paths["mask"], encode_png(np.where(s.object_id > 0, 255, 0).astype(np.uint8)))
        paths["out"].unlink(missing_ok=True)
        values = {key: str(p.resolve()) for key, p in paths.items()}
        values.update(images=[str(ds.image_path(v).resolve()) for v in s.views], dataset=root)
        est = None
        if invoke(options, values, d, name, out) is None:
            try:
                est = read_npy(paths["out"], s.normals_cam.shape)
                out.raw_files.append(f"{name}/normals.npy")
            except InputError as exc:  # the method's failure: no normals
                failed_output(out, name, str(exc))
        n_cv = np.full(s.normals_cam.shape, np.nan) if est is None else est @ DILIGENT_FROM_OPENCV_CAM.T
        pre = f"{name}." if len(sets) > 1 else ""
        groups = {"all": s.object_id > 0, **{obj: s.object_id == oid for obj, oid in s.objects.items()}}
        for group, m in groups.items():
            if m.any():
                r = normal_metrics(s.normals_cam, n_cv, m)
                out.results[f"{pre}{group}.normals"] = r
                out.metrics.update({f"{pre}{k2}": v for k2, v in normals_headline(r, group).items()})
    return out


def cloud(ds, out_dir, options) -> RunOutput:
    """The ``cloud`` kind (module docstring)."""
    images, ply = out_path(out_dir, "images/x").parent, out_path(out_dir, "cloud.ply")
    shutil.rmtree(images, ignore_errors=True)
    ply.unlink(missing_ok=True)
    images.mkdir(parents=True)
    for v in ds.views:
        shutil.copy(ds.image_path(v), images / f"{check_view_name(v)}.png")
    out = RunOutput()
    why = invoke(options, {"images": str(images.resolve()), "out": str(ply.resolve()),
                           "dataset": str(Path(ds.root).resolve())}, Path(out_dir) / "logs", "cloud", out)
    shutil.rmtree(images, ignore_errors=True)  # the copies of the images
    rec = np.zeros((0, 3))
    if why is None:
        try:
            rec = read_geometry(ply).vertices
            out.raw_files.append("cloud.ply")
        except InputError as exc:  # an unreadable file: scored as an empty cloud
            failed_output(out, "cloud", str(exc))
    V, F = ds.mesh()
    mesh = MeshSurface(V, F)
    gt = sample_mesh_surface(V, F, CLOUD_GT_SAMPLES, seed=0)
    out.results[f"tanks_and_temples@{CLOUD_TAU_M:g}m"] = tanks_and_temples(rec, gt, CLOUD_TAU_M, gt_mesh=mesh)
    out.results["chamfer"] = chamfer(rec, gt, gt_mesh=mesh)
    out.metrics.update(cloud_headline(out.results))
    return out


def triangulation(ds, out_dir, options) -> RunOutput:
    """The ``triangulation`` kind (module docstring)."""
    def answer(task_dir: Path, points_dir: Path, pairs: list, out: RunOutput) -> None:
        shutil.rmtree(points_dir, ignore_errors=True)
        points_dir.mkdir(parents=True)
        invoke(options, {"task": str(task_dir.resolve()), "out": str(points_dir.resolve()),
                         "dataset": str(Path(ds.root).resolve())}, Path(out_dir) / "logs" / task_dir.name,
               task_dir.name, out)

    return triangulate_runner.opencv(ds, Path(out_dir), options, answer=answer)


def dlt(ds, out_dir, options) -> RunOutput:
    """The ``dlt`` kind (module docstring)."""
    def fit(view: str, kind: str, x: np.ndarray, Xw: np.ndarray, out: RunOutput) -> np.ndarray:
        item = f"{check_view_name(view)}/{kind}"
        d = Path(out_dir) / "work" / item
        d.mkdir(parents=True, exist_ok=True)
        points, path = d / "points.npy", d / "P.txt"
        np.save(points, np.concatenate([x, Xw], axis=1))
        path.unlink(missing_ok=True)
        values = {"points": str(points.resolve()), "view": check_view_name(view), "out": str(path.resolve()),
                  "dataset": str(Path(ds.root).resolve())}
        if invoke(options, values, d, item, out) is None:
            try:
                return read_projection_matrix(path)
            except InputError as exc:  # the method's failure
                failed_output(out, item, str(exc))
        return np.full((3, 4), np.nan)

    return dlt_runner.linear(ds, Path(out_dir), options, estimate=fit)
