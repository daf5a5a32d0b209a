"""``recon-eval normals``: a normal map (photometric stereo, shape from shading, a monocular normal
estimator) against a dataset's truth normals with DiLiGenT's metrics, per object and over all
objects; optionally the method's albedo (up to the global scale) and, for uncalibrated photometric
stereo, its light directions and intensities (docs/metrics.md, "Photometric stereo")."""
from __future__ import annotations

import numpy as np

from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.normals import albedo_metrics, light_metrics, normal_metrics
from recon_eval.readers.normal_map import read_light_rows, read_normal_map
from recon_eval.readers.npy import read_npy
from recon_eval.readers.photometric import photometric_sets
from recon_eval.readers.scenegen_dataset import is_dataset
from recon_eval.tasks.headlines import normals_headline
from scenegen.dataset import Dataset
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.conventions import DILIGENT_FROM_OPENCV_CAM

FRAMES = ("diligent", "opencv")


def arguments(p) -> None:
    p.add_argument("est", help="estimated normal map: .npy (H, W, 3), .exr (R G B or X Y Z), .png ((n + 1) / 2)")
    p.add_argument("gt", help="the truth: a scenegen dataset folder")
    p.add_argument("--view", help="the view whose truth normals to use (default: the first view of the dataset's "
                                  "first photometric stereo set)")
    p.add_argument("--frame", choices=FRAMES, default="diligent",
                   help="axes of the estimate: diligent (x right, y up, z toward the camera; default) or opencv "
                        "(x right, y down, z forward)")
    p.add_argument("--normalize", action="store_true",
                   help="scale non-zero estimates to unit length first (DiLiGenT's code does not)")
    p.add_argument("--object", action="append", dest="objects", metavar="NAME",
                   help="score only these spec objects (default: every object, and each apart)")
    p.add_argument("--albedo", metavar="FILE", help="estimated albedo .npy (H, W) or (H, W, 3), scored up to scale")
    p.add_argument("--lights", metavar="FILE", help="estimated light directions (light_directions.txt: one row "
                                                    "x y z per image of the set, in --frame axes)")
    p.add_argument("--light-intensities", metavar="FILE", help="estimated light intensities (light_intensities.txt)")


def _to_opencv(n: np.ndarray, frame: str) -> np.ndarray:
    return n @ DILIGENT_FROM_OPENCV_CAM.T if frame == "diligent" else n


def score(a):
    if not is_dataset(a.gt):
        raise InputError(f"{a.gt}: expected a scenegen dataset folder (manifest.json) as the truth")
    try:
        sets = photometric_sets(a.gt)
    except NotApplicable:
        sets = []
    try:
        ds = Dataset(a.gt)
        view = a.view or (sets[0].views[0] if sets else None)
        if view is None:
            raise InputError(f"{a.gt}: no photometric stereo set: name the view with --view")
        truth = ds.truth(ds.check_view(view))
        albedo_gt = ds.albedo(view) if a.albedo else None
    except (DatasetError, KeyError) as exc:
        raise InputError(f"{a.gt}: {exc.args[0]}" if isinstance(exc, KeyError) else str(exc)) from None
    est = read_normal_map(a.est)
    gt_n = truth[TruthKind.NORMALS_CAM].astype(np.float64)
    if est.shape != gt_n.shape:
        raise InputError(f"{a.est}: normal map shape {est.shape} differs from view {view!r}'s {gt_n.shape}")
    if a.normalize:
        norm = np.linalg.norm(est, axis=-1, keepdims=True)
        est = np.where(norm > 0, est / np.where(norm > 0, norm, 1.0), est)
    est_cv = _to_opencv(est, a.frame)
    ids = {o["name"]: int(o["object_id"]) for o in ds.objects}
    unknown = [n for n in (a.objects or []) if n not in ids]
    if unknown:
        raise InputError(f"--object {unknown[0]!r}: not an object of the dataset (objects: {', '.join(ids)})")
    names = a.objects or list(ids)
    object_id = truth[TruthKind.OBJECT_ID]
    groups = {"all": np.isin(object_id, [ids[n] for n in names]), **{n: object_id == ids[n] for n in names}}
    res = {}
    for name, m in groups.items():
        if m.any():
            res[f"{name}.normals"] = normal_metrics(gt_n, est_cv, m)
    if a.albedo:
        if albedo_gt is None:
            raise InputError(f"{a.gt}: view {view!r} has no albedo truth (spec truth.albedo)")
        alb = read_npy(a.albedo)
        if alb.ndim == 2:
            albedo_gt = albedo_gt.mean(axis=-1)
        res["all.albedo"] = albedo_metrics(albedo_gt, alb, groups["all"])
    if a.lights or a.light_intensities:
        s = next((s for s in sets if view in s.views), None)
        if s is None or not a.lights:
            raise InputError("--lights needs a view of a photometric stereo set (and --light-intensities needs --lights)")
        d = _to_opencv(read_light_rows(a.lights, len(s.views), "light direction x y z"), a.frame)
        e = read_light_rows(a.light_intensities, len(s.views), "light intensity") if a.light_intensities else None
        res["lights"] = light_metrics(s.directions_cam, d, None if e is None else s.intensities,
                                      None if e is None else e)
    inputs = {"est": a.est, "gt": a.gt, "view": view, "frame": a.frame, "normalized": bool(a.normalize),
              "objects": names, "albedo": a.albedo, "lights": a.lights,
              "set_views": list(next((s.views for s in sets if view in s.views), ()))}
    return inputs, res, no_figures


def metrics(a, res) -> dict:
    """``metrics`` of ``normals --json``: the names a photometric stereo run gives the same numbers."""
    out = {}
    for key, r in res.items():
        if key.endswith(".normals"):
            out.update(normals_headline(r, key.removesuffix(".normals")))
    if "all.albedo" in res:
        out["all.albedo_rel_mae"] = res["all.albedo"].rel_mae
    return out


COMMANDS = {"normals": scored(arguments, score, metrics)}
