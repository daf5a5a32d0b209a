"""The ``dlt``, ``triangulation-task`` and ``triangulation`` subcommands of ``recon-eval``
(registered in :mod:`recon_eval.cli.registry`). File formats and metrics: docs/metrics.md, "DLT camera matrices" and
"Triangulation".

Examples::

    recon-eval dlt P.txt DATASET --view obj_0000                   # truth K, pose, held-out points
    recon-eval dlt P.txt --K K.txt --pose pose.json                # any truth
    recon-eval dlt P.txt DATASET --view obj_0000 --projective-points pts.txt   # projective frame
    recon-eval triangulation-task DATASET -o TASK --sigma 1.0      # pairs: crossview/index.json
    recon-eval triangulation-task DATASET -o TASK --pairs a:b      # a crossview pair (its visibility)
    recon-eval triangulation TASK EST_DIR                          # EST_DIR/<pair>.txt: X Y Z rows
    recon-eval triangulation TASK                                  # OpenCV triangulatePoints
"""
from __future__ import annotations

import numpy as np

from recon_eval.cli.common import dataset_view
from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.dlt import decompose_projection, project_with_P, score_projection, score_projection_projective
from recon_eval.metrics.triangulation import projection_matrix, triangulation_angle_deg
from recon_eval.readers.matrix import read_matrix3
from recon_eval.readers.npy import read_npy
from recon_eval.readers.pose_file import read_pose
from recon_eval.readers.rows import read_projection_matrix, read_rows
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure
from recon_eval.tasks import triangulation_task as tt
from recon_eval.tasks.board_truth import MIN_THICKNESS_RATIO, lookup_board_points, thickness_ratio
from scenegen.geometry.twoview import undistorted_pixels


def dlt_arguments(p) -> None:
    p.add_argument("P", help="estimated 3x4 camera matrix P ~ K [R | t] (text: 3 rows of 4 numbers, or .npy), "
                             "any scale and sign, undistorted OpenCV pixels")
    p.add_argument("gt", nargs="?", help="truth dataset folder (K and cam_from_world of --view, held-out truth "
                                         "points); or give --K and --pose")
    p.add_argument("--view", help="dataset truth: the view P belongs to (required when the dataset has several)")
    p.add_argument("--points", type=int, default=5000, help="dataset truth: held-out truth points for reprojection")
    p.add_argument("--K", dest="K_file", metavar="K.txt",
                   help="non-dataset truth: the 3x3 intrinsic matrix (.txt/.npy/.json)")
    p.add_argument("--pose", help="non-dataset truth: the view's pose (.json {R, t} / 3x4 / 4x4, .npy, .txt)")
    p.add_argument("--pose-convention", choices=["cam_from_world", "world_from_cam"], default="cam_from_world",
                   help="what a bare matrix in --pose holds")
    p.add_argument("--points-world", help="non-dataset truth: (N, 3) .npy world points for reprojection")
    p.add_argument("--pixels", help="non-dataset truth: (N, 2) .npy undistorted pixels observing them")
    p.add_argument("--projective-points", metavar="PTS.txt",
                   help="P is a camera of a projective reconstruction; these are its points: 'BOARD ID X Y Z [W]' "
                        "rows (dataset truth: matched to scene/targets/BOARD.json point ids) or 'X Y Z [W]' rows "
                        "one to one with --truth-points. Scored after the 15-DoF projective alignment")
    p.add_argument("--truth-points", metavar="TRUTH.txt",
                   help="non-dataset projective form: 'X Y Z' rows (metres), one per --projective-points row")


def task_arguments(p) -> None:
    p.add_argument("dataset", help="dataset folder (truth cameras, points and visibility)")
    p.add_argument("-o", "--out", required=True, metavar="TASK", help="task folder to write")
    p.add_argument("--sigma", type=float, default=1.0, help="Gaussian pixel noise per coordinate, px (default 1)")
    p.add_argument("--pairs", nargs="+", metavar="V1:V2",
                   help="view pairs (default: crossview/index.json pairs); each needs correspondence truth "
                        "(the spec's crossview.pairs)")
    p.add_argument("--count", type=int, default=2000, help="truth points per pair (default 2000)")
    p.add_argument("--seed", type=int, default=0, help="seed of the point selection and the noise")


def triangulation_arguments(p) -> None:
    p.add_argument("task", help="task folder written by recon-eval triangulation-task")
    p.add_argument("est", nargs="?", help="folder of answers <pair>.txt: one 'X Y Z' row (world, metres) per "
                                          "observation row; default: score OpenCV's triangulatePoints")


# --- dlt --------------------------------------------------------------------------------------
def score_dlt(a):
    if a.points < 1:
        raise InputError(f"--points must be >= 1, got {a.points}")
    P = read_projection_matrix(a.P)
    inputs = {"P": a.P, "gt": a.gt, "projective_points": a.projective_points}
    ds = None
    X = uv = None
    if a.gt is not None:
        if a.K_file or a.pose:
            raise InputError("give either a dataset truth or --K and --pose, not both")
        if not is_dataset(a.gt):
            raise InputError(f"{a.gt}: not a scenegen dataset folder (for another truth give --K K.txt --pose POSE)")
        ds = read_dataset(a.gt)
        view = dataset_view(ds, a.view, "a DLT truth")
        cam, pose = ds.camera(view)
        K, R, t = cam.K, pose.R, pose.t
        inputs.update(view=view, gt_kind="scenegen-dataset cameras.json", camera_model=cam.model)
        if not a.projective_points:
            uv, X = ds.points_at_pixels(view, max_points=a.points)
            uv = undistorted_pixels(cam, uv)  # P has no distortion: compare with undistorted pixels
            inputs["held_out_points"] = len(X)
    else:
        if a.view:
            raise InputError("--view needs a dataset truth")
        if not (a.K_file and a.pose):
            raise InputError("dlt needs a truth: a dataset folder (with --view), or --K K.txt and --pose POSE")
        K = read_matrix3(a.K_file, key="K")
        R, t = read_pose(a.pose, a.pose_convention)
        if not (np.all(np.isfinite(K)) and np.all(np.isfinite(R)) and np.all(np.isfinite(t))):
            raise InputError(f"{a.K_file}, {a.pose}: the truth K and pose must be finite")
        inputs.update(K=a.K_file, pose=a.pose, pose_convention=a.pose_convention, gt_kind="K and pose files")
        if a.points_world or a.pixels:
            if not (a.points_world and a.pixels):
                raise InputError("reprojection needs both --points-world and --pixels")
            X, uv = read_npy(a.points_world, (None, 3)), read_npy(a.pixels, (None, 2))
            if len(X) != len(uv):
                raise InputError(f"{a.points_world} ({len(X)} points) and {a.pixels} ({len(uv)} pixels) differ "
                                 f"in length")
    res = {}
    if a.projective_points:
        if ds is not None:
            rows = read_rows(a.projective_points, "BOARD ID X Y Z [W]", (3, 4), n_labels=2)
            X_true = lookup_board_points(ds, rows, a.projective_points)
        else:
            if not a.truth_points:
                raise InputError("--projective-points without a dataset needs --truth-points TRUTH.txt")
            rows = read_rows(a.projective_points, "X Y Z [W]", (3, 4))
            X_true = np.asarray([r.values for r in read_rows(a.truth_points, "X Y Z", (3,))]).reshape(-1, 3)
            if len(X_true) != len(rows):
                raise InputError(f"{a.truth_points}: {len(X_true)} rows, {a.projective_points} has {len(rows)}")
        X_proj = np.asarray([np.r_[r.values, 1.0][:4] for r in rows]).reshape(-1, 4)
        bad = [r.line for r, x in zip(rows, X_proj) if not np.all(np.isfinite(x)) or x[3] == 0]
        if bad:
            raise InputError(f"{a.projective_points}:{bad[0]}: a projective point must be finite with W != 0")
        _check_3d(X_true, a.projective_points)
        pix = project_with_P(projection_matrix(K, R, t), X_true)  # the truth camera's undistorted pixels
        if np.all(np.isfinite(P)):
            res["dlt"] = score_projection_projective(P, X_proj, X_true, K, (R, t), pix)
        else:  # a failed estimate is scored (every error inf), not refused
            res["dlt"] = score_projection(P, K, (R, t), X_true, pix)
        inputs.update(alignment="projective15", n_points=len(X_true), reprojection="the given points")
    else:
        res["dlt"] = score_projection(P, K, (R, t), X, uv)
        inputs["alignment"] = "none"
        if not res["dlt"].failed:
            Ke, Re, te = decompose_projection(P)
            res["decomposition"] = {"K": Ke, "R": Re, "t": te, "center_world_m": -Re.T @ te}
    return inputs, res, no_figures


def _check_3d(X, where) -> None:
    r = thickness_ratio(X)
    if r < MIN_THICKNESS_RATIO:
        raise InputError(f"{where}: the {len(X)} truth points are coplanar or too few (thickness ratio {r:.2g} < "
                         f"{MIN_THICKNESS_RATIO:g}): the 15-DoF projective alignment needs >= 5 points not on a plane")


# --- triangulation ----------------------------------------------------------------------------
def score_task(a):
    if not (a.sigma >= 0 and np.isfinite(a.sigma)):
        raise InputError(f"--sigma must be a finite number >= 0, got {a.sigma}")
    if a.count < 1:
        raise InputError(f"--count must be >= 1, got {a.count}")
    ds = read_dataset(a.dataset)
    views, skipped = tt.dataset_pairs(ds, a.pairs)
    pairs = [tt.build_pair(ds, v1, v2, a.sigma, a.count, a.seed) for v1, v2 in views]
    path = tt.write_task(a.out, pairs, {"dataset": str(a.dataset), "scene": ds.scene_name, "sigma_px": a.sigma,
                                        "seed": a.seed, "count": a.count})
    res = {"pairs": {tp.name: {"n_points": len(tp.points_true), "median_angle_deg": float(np.median(
        triangulation_angle_deg(tp.points_true, -tp.cam1_from_world[0].T @ tp.cam1_from_world[1],
                                -tp.cam2_from_world[0].T @ tp.cam2_from_world[1])))} for tp in pairs}}
    return {"dataset": a.dataset, "task": str(path), "sigma_px": a.sigma, "seed": a.seed, "count": a.count,
            "skipped_zero_baseline_pairs": [f"{i}:{j}" for i, j in skipped]}, res, no_figures


def _bins_table(score) -> dict:
    return {tt.bin_label(b): b for b in score.bins if b.n}


def score_triangulation(a):
    doc, pairs = tt.read_task(a.task)
    ref = {tp.name: tt.reference_points(tp) for tp in pairs}
    if a.est:
        est, notes = tt.read_estimates(a.est, pairs)
        method = "user"
    else:
        est, notes, method = ref, {}, "opencv-triangulatePoints (reference)"
    res = tt.score_task(pairs, est)
    pooled = res["all_pairs"]
    res["all_pairs.bins"] = _bins_table(pooled)
    inputs = {"task": a.task, "est": a.est, "method": method, "sigma_px": doc.get("sigma_px"),
              "dataset": doc.get("dataset"), "pairs": [tp.name for tp in pairs], **notes}

    def figures():
        curves = {("estimate" if a.est else "OpenCV triangulatePoints"): tt.bin_curve(pooled)}
        if a.est:
            curves["OpenCV triangulatePoints (reference)"] = tt.bin_curve(tt.score_task(pairs, ref)["all_pairs"])
        fx = [decompose_projection(tp.P1)[0][0, 0] for tp in pairs]
        sigma = doc.get("sigma_px")
        guide = (float(sigma), float(np.median(fx))) if isinstance(sigma, (int, float)) and sigma > 0 else None
        return [Figure("Error vs triangulation angle",
                       plots.triangulation_angle_figure(curves, title=f"all pairs, sigma {sigma} px",
                                                        points=(pooled.angle_deg, pooled.err_m, pooled.rel_err),
                                                        guide=guide),
                       "median per angle bin ([lo, hi) bars), points in grey; failures count in the medians")]

    return inputs, res, figures


COMMANDS = {"dlt": scored(dlt_arguments, score_dlt), "triangulation-task": scored(task_arguments, score_task),
            "triangulation": scored(triangulation_arguments, score_triangulation)}
