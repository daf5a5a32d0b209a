"""More output kinds of a user's command (:mod:`recon_eval.runners.external`, which declares
them in its ``KINDS``): optical flow, depth maps and essential matrices, each run per item and
scored by the same code, under the same headline names, as the built-in methods and the scoring
command of its task (docs/ci.md, "Your own estimator").

* ``flow``: per flow pair (a sequence's frame pairs, else both directions of each cross-view pair,
  as the built-in flow methods): ``{image1} {image2}`` -> ``{out}`` a Middlebury ``.flo`` (u, v px,
  image1 -> image2); scored as ``opencv-flow-dis`` (:func:`recon_eval.metrics.flow.flow_metrics`).
* ``depth``: per view: ``{image}`` -> ``{out}`` an (H, W) ``.npy`` of z-depth in metres (NaN, inf
  or <= 0: no estimate); Eigen's metrics over the views without alignment and with per-image
  median scaling (``recon-eval depth``).
* ``essential``: per cross-view pair: ``{images}`` and the truth intrinsics ``{k1} {k2}`` (3x3
  text; the images are the stored ones, distorted where the camera is) -> ``{out}`` E (3x3 text,
  x2n^T E x1n = 0 for normalised undistorted coordinates xn = K^-1 x); its relative pose is
  recovered on the truth correspondences (``cv2.recoverPose``) and scored as the built-in E methods.

* ``homography``: per cross-view pair and planar object with a truth homography: ``{images}``,
  ``{plane}`` (its name) and ``{mask}`` (a PNG of image 1, 255 on the plane's pixels, from the
  object-id truth) -> ``{out}`` H (3x3 text, x2 ~ H x1 in undistorted pixels); the mean corner
  error against the truth H, as the built-in H methods (``<plane>.mace_px``).

A failed invocation or an unreadable output is a failed estimate of that item (NaN: the metrics'
own failure), never dropped.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.depth import eigen_depth_metrics
from recon_eval.metrics.epipolar import homography_mace, pose_error_from_fundamental
from recon_eval.metrics.flow import flow_metrics
from recon_eval.readers.flow import read_flow
from recon_eval.readers.matrix import read_matrix3
from recon_eval.readers.npy import read_npy
from recon_eval.runners import flow as flow_runner
from recon_eval.runners.common import RunOutput, crossview_pairs, out_path
from recon_eval.runners.external import failed_output, invoke
from recon_eval.tasks.fmatrix_pair import pair_truth
from recon_eval.tasks.headlines import depth_headline, flow_headline
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.files import atomic_write_bytes
from scenegen.dataset.layout import check_name, check_view_name

#: The alignments a depth method is scored under (``recon-eval depth --alignment``).
DEPTH_ALIGNMENTS = ("none", "median")


def _read(path: Path, out, item: str, reader):
    """``reader(path)``, or None after recording the method's failure (no file, unreadable)."""
    if not path.is_file():
        failed_output(out, item, f"wrote no {path.name}")
        return None
    try:
        return reader(path)
    except InputError as exc:
        failed_output(out, item, str(exc))
        return None


def _shaped(est, shape, out, item: str, path: Path):
    if est is not None and est.shape != shape:
        failed_output(out, item, f"{path.name}: shape {est.shape}, expected the truth's {shape}")
        return None
    return est


def flow(ds, out_dir, options) -> RunOutput:
    """The ``flow`` kind (module docstring)."""
    out, est, gts, states = RunOutput(), [], [], []
    root = str(Path(ds.root).resolve())
    for i, j in flow_runner.pairs(ds):
        key = f"{check_view_name(i)}__{check_view_name(j)}"
        path = out_path(out_dir, f"flow/{key}.flo")
        path.unlink(missing_ok=True)
        values = {"image1": str(ds.image_path(i).resolve()), "image2": str(ds.image_path(j).resolve()),
                  "view1": i, "view2": j, "out": str(path.resolve()), "dataset": root}
        why = invoke(options, values, Path(out_dir) / "logs" / key, key, out)
        g, st, _ = ds.flow_truth(i, j)
        f = None if why else _shaped(_read(path, out, key, read_flow), g.shape, out, key, path)
        if f is not None:
            out.raw_files.append(f"flow/{key}.flo")
        est.append(np.full_like(g, np.nan) if f is None else f)
        gts.append(g)
        states.append(st)
    r = flow_metrics(est, gts, states)
    out.results["flow"] = r
    out.metrics.update(flow_headline(r))
    out.notes["pairs"] = len(est)
    return out


def _depth_reader(path: Path) -> np.ndarray:
    return read_npy(path, (None, None))


def depth(ds, out_dir, options) -> RunOutput:
    """The ``depth`` kind (module docstring)."""
    out, est, gts = RunOutput(), [], []
    root = str(Path(ds.root).resolve())
    for v in ds.views:
        name = check_view_name(v)
        path = out_path(out_dir, f"depth/{name}.npy")
        path.unlink(missing_ok=True)
        values = {"image": str(ds.image_path(v).resolve()), "view": name, "out": str(path.resolve()),
                  "dataset": root}
        why = invoke(options, values, Path(out_dir) / "logs" / name, name, out)
        g = ds.depth(v)
        d = None if why else _shaped(_read(path, out, name, _depth_reader), g.shape, out, name, path)
        if d is not None:
            out.raw_files.append(f"depth/{name}.npy")
        est.append(np.full(g.shape, np.nan) if d is None else np.where(d > 0, d, np.nan))
        gts.append(g)
    for alignment in DEPTH_ALIGNMENTS:
        r = eigen_depth_metrics(est, gts, alignment=alignment)
        out.results[f"eigen_{alignment}"] = r
        out.metrics.update(depth_headline(r, alignment))
    return out


def essential(ds, out_dir, options) -> RunOutput:
    """The ``essential`` kind (module docstring)."""
    pairs = crossview_pairs(ds)
    out = RunOutput()
    root = str(Path(ds.root).resolve())
    for i, j in pairs:
        key = f"{check_view_name(i)}__{check_view_name(j)}"
        if ds.truth_fundamental(i, j)[0] is None:
            out.notes[key] = "skipped: zero baseline (one camera centre), no essential matrix"
            continue
        truth = pair_truth(ds, i, j, pixels="undistorted")
        epath = out_path(out_dir, f"{key}/E.txt")
        epath.unlink(missing_ok=True)
        kpaths = [out_path(out_dir, f"{key}/K{n}.txt") for n in (1, 2)]
        for kp, K in zip(kpaths, (truth.K1, truth.K2)):
            np.savetxt(kp, K, fmt="%.17g")
        images = [str(ds.image_path(i).resolve()), str(ds.image_path(j).resolve())]
        values = {"images": images, "image1": images[0], "image2": images[1], "view1": i, "view2": j,
                  "k1": str(kpaths[0].resolve()), "k2": str(kpaths[1].resolve()), "out": str(epath.resolve()),
                  "dataset": root}
        why = invoke(options, values, epath.parent, key, out)
        E = None if why else _read(epath, out, key, lambda p: read_matrix3(p, key="E"))
        if E is None:
            E = np.full((3, 3), np.nan)
        else:
            out.raw_files.append(f"{key}/E.txt")
        F = np.linalg.inv(truth.K2).T @ E @ np.linalg.inv(truth.K1)  # the same pose, through the truth K
        pe = pose_error_from_fundamental(F, truth.K1, truth.K2, truth.x1, truth.x2, truth.R, truth.t)
        if pe.failed and not why and out.notes.get(key, {}).get("failed") is None:
            out.warnings.append(f"{key}: the estimated E is {pe.failure_reason}: scored as a failed estimate "
                                f"(pose_err_deg inf)")
        out.results[f"{key}.relative_pose"] = pe
        pre = "" if len(pairs) == 1 else f"{key}."
        out.metrics.update({pre + "pose_err_deg": pe.pose_err_deg, pre + "rot_err_deg": pe.rot_err_deg})
    if not out.results:
        raise NotApplicable(f"{ds.root}: the cross-view pairs are all zero-baseline: no essential matrix to estimate")
    return out


def homography(ds, out_dir, options) -> RunOutput:
    """The ``homography`` kind (module docstring)."""
    pairs = crossview_pairs(ds)
    out = RunOutput()
    root = str(Path(ds.root).resolve())
    for i, j in pairs:
        planes = ds.read(ds.dataset.crossview.twoview, i, j).homographies
        ci, _ = ds.camera(i)
        for plane, H_gt in planes.items():
            key = f"{check_view_name(i)}__{check_view_name(j)}/{check_name('plane', plane)}"
            d = Path(out_dir) / key
            d.mkdir(parents=True, exist_ok=True)
            mask, hpath = d / "mask.png", d / "H.txt"
            atomic_write_bytes(mask, encode_png(np.where(ds.object_ids(i) == ds.object_id(plane), 255, 0)
                                                .astype(np.uint8)))
            hpath.unlink(missing_ok=True)
            images = [str(ds.image_path(i).resolve()), str(ds.image_path(j).resolve())]
            values = {"images": images, "image1": images[0], "image2": images[1], "view1": i, "view2": j,
                      "plane": plane, "mask": str(mask.resolve()), "out": str(hpath.resolve()), "dataset": root}
            why = invoke(options, values, d, key, out)
            H = None if why else _read(hpath, out, key, lambda p: read_matrix3(p, key="H"))
            if H is None:
                H = np.full((3, 3), np.nan)
            else:
                out.raw_files.append(f"{key}/H.txt")
            r = homography_mace(H, H_gt, ci.width, ci.height)
            if r.failed and not why and out.notes.get(key, {}).get("failed") is None:
                out.warnings.append(f"{key}: the estimated H is {r.failure_reason}: scored as a failed estimate "
                                    f"(mace_px inf)")
            out.results[f"{i}__{j}.{plane}.homography"] = r
            pre = "" if len(pairs) == 1 else f"{i}__{j}."
            out.metrics[f"{pre}{plane}.mace_px"] = r.mace_px
    if not out.results:
        raise NotApplicable(f"{ds.root}: no cross-view pair has a planar object with a truth homography")
    return out
