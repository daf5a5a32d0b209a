"""The whole BOP19 evaluation of one result (``eval_bop19_pose.py``): VSD, MSSD and MSPD errors
of every scored estimate (with eval_calc_errors.py's bounding-sphere shortcuts), their average
recalls and AR, and ADD / ADD-S recall (docs/metrics.md, "Object pose")."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from recon_eval.metrics.objects_bop import (
    add, add_s, mspd, mssd, sphere_projections_overlap, symmetry_transforms, vsd,
)
from recon_eval.metrics.objects_bop_recall import (
    ADD_THRESHOLD, MSPD_REFERENCE_WIDTH_PX, MSPD_THRESHOLDS, MSSD_THRESHOLDS, VSD_TAUS, VSD_THRESHOLDS,
    Bop19Result, RecallCurve, estimate_errors, mean_time_per_image, recall_curve, valid_truths,
)
from recon_eval.metrics.objects_depth import render_depth

#: eval_bop19_pose.py's vsd_deltas: 15 mm for every dataset but ITODD (5 mm).
VSD_DELTA_MM = 15.0


@dataclass(frozen=True)
class BopModel:
    vertices: np.ndarray  # (V, 3) model units (BOP: mm); MSSD/MSPD/ADD use these points
    faces: np.ndarray  # (F, 3) for the VSD depth renders
    diameter: float  # models_info.json "diameter"
    info: dict  # the models_info.json entry (symmetries)


@dataclass(frozen=True)
class BopView:
    K: np.ndarray  # (3, 3) scene_camera.json cam_K
    depth: np.ndarray | None  # (H, W) the scene's depth image times depth_scale (mm); None: no VSD
    width: int
    height: int


def bop19_evaluate(estimates, targets, gts: dict, views: dict, models: dict, *,
                   vsd_delta: float = VSD_DELTA_MM) -> Bop19Result:
    """BOP19 scores of ``estimates`` (:class:`PoseEstimate`) for ``targets`` against ``gts``
    ((scene_id, im_id) -> [:class:`GtPose`] in scene_gt order), ``views`` ((scene_id, im_id) ->
    :class:`BopView`) and ``models`` (obj_id -> :class:`BopModel`). Without depth images VSD is
    not computable: ``ar_vsd`` and ``ar`` are NaN."""
    syms = {oid: symmetry_transforms(m.info) for oid, m in models.items()}
    renders: dict = {}

    def model_depth(oid, R, t, view: BopView):
        key = (oid, view.K.tobytes(), np.asarray(R).tobytes(), np.asarray(t).tobytes(), view.width, view.height)
        if key not in renders:
            m = models[oid]
            renders[key] = render_depth(m.vertices, m.faces, R, t, view.K, view.width, view.height)
        return renders[key]

    def vsd_error(e, g, key):
        view, m = views[key], models[e.obj_id]
        if not sphere_projections_overlap(0.5 * m.diameter, e.t, g.t):
            return (1.0,) * len(VSD_TAUS)
        return vsd(model_depth(e.obj_id, e.R, e.t, view), model_depth(g.obj_id, g.R, g.t, view), view.depth,
                   view.K, delta=vsd_delta, taus=VSD_TAUS, diameter=m.diameter)

    def near(e, g) -> bool:  # eval_calc_errors.py's spheres_overlap (else the error is inf)
        return bool(np.linalg.norm(np.asarray(e.t, float).reshape(3) - np.asarray(g.t, float).reshape(3))
                    < models[e.obj_id].diameter)

    def mssd_error(e, g, key):
        return (mssd(e.R, e.t, g.R, g.t, models[e.obj_id].vertices, syms[e.obj_id]) if near(e, g) else np.inf,)

    def mspd_error(e, g, key):
        return (mspd(e.R, e.t, g.R, g.t, views[key].K, models[e.obj_id].vertices, syms[e.obj_id]),)

    def add_errors(e, g, key):
        if not near(e, g):
            return (np.inf, np.inf)
        v = models[e.obj_id].vertices
        return (add(e.R, e.t, g.R, g.t, v), add_s(e.R, e.t, g.R, g.t, v))

    valid = valid_truths(targets, gts)

    def per_diameter(e):
        return 1.0 / models[e.obj_id].diameter

    def per_width(e):
        return MSPD_REFERENCE_WIDTH_PX / views[(e.scene_id, e.im_id)].width

    errs_mssd = estimate_errors(mssd_error, estimates, targets, gts)
    mssd_curve = recall_curve(errs_mssd, valid, MSSD_THRESHOLDS, scale=per_diameter)
    mspd_curve = recall_curve(estimate_errors(mspd_error, estimates, targets, gts), valid, MSPD_THRESHOLDS,
                              scale=per_width)
    has_depth = all(views[(t.scene_id, t.im_id)].depth is not None for t in targets)
    if has_depth:
        vsd_curve = recall_curve(estimate_errors(vsd_error, estimates, targets, gts), valid, VSD_THRESHOLDS,
                                 n_values=len(VSD_TAUS))
    else:
        vsd_curve = RecallCurve((), (), float("nan"))
    errs_add = estimate_errors(add_errors, estimates, targets, gts)
    add_r = recall_curve(errs_add, valid, (ADD_THRESHOLD,), scale=per_diameter).average_recall
    adds_r = recall_curve([_pick(e, 1) for e in errs_add], valid, (ADD_THRESHOLD,),
                          scale=per_diameter).average_recall
    ad_errs = [_pick(e, 1 if _is_symmetric(models[e.obj_id].info) else 0) for e in errs_add]
    ad_r = recall_curve(ad_errs, valid, (ADD_THRESHOLD,), scale=per_diameter).average_recall
    ar = float(np.mean([vsd_curve.average_recall, mssd_curve.average_recall, mspd_curve.average_recall]))
    return Bop19Result(
        ar=ar, ar_vsd=vsd_curve.average_recall, ar_mssd=mssd_curve.average_recall,
        ar_mspd=mspd_curve.average_recall, add_recall=add_r, adds_recall=adds_r, ad_recall=ad_r,
        n_targets=int(sum(sum(f) for f in valid.values())), n_estimates=len(list(estimates)),
        n_scored=len(errs_mssd), mean_time_per_image_s=mean_time_per_image(estimates),
        vsd=vsd_curve, mssd=mssd_curve, mspd=mspd_curve,
    )


def _pick(e, index: int):
    """The estimate's errors reduced to the ``index``-th value."""
    return replace(e, errors={g: (v[index],) for g, v in e.errors.items()})


def _is_symmetric(info: dict) -> bool:
    """bop_toolkit's ``symmetric_obj_ids`` (dataset_params.py) is a per-dataset list; here: a
    model that declares any symmetry in models_info.json."""
    return bool(info.get("symmetries_discrete") or info.get("symmetries_continuous"))
