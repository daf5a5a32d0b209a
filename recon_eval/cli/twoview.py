"""``recon-eval fmatrix`` and ``recon-eval homography``: two-view estimates against exact truth
(docs/metrics.md, "Fundamental matrices and homographies")."""
from __future__ import annotations

import numpy as np

from recon_eval.cli.common import image_size
from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.epipolar import (fundamental_degeneracy, fundamental_metrics, homography_degeneracy,
                                         homography_mace,
                                         homography_summary, pose_error_from_fundamental, sampson_sq_px2,
                                         zhang_f_distance)
from recon_eval.readers.matrix import read_matrix3
from recon_eval.readers.npy import read_npy
from recon_eval.readers.registry import read_image
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure
from scenegen.geometry.twoview import fundamental


# --- fundamental matrix -----------------------------------------------------------------------
def fmatrix_arguments(p) -> None:
    p.add_argument("f_est", help="estimated F (.txt/.npy/.json)")
    p.add_argument("--matches", help="truth correspondences .npy (N, 4): x1 y1 x2 y2, OpenCV pixels")
    p.add_argument("--f-gt", help="truth F for Zhang's F-distance")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), help="image size for Zhang's F-distance")
    p.add_argument("--dataset", help="dataset folder: truth F, correspondences, K, size and images of --views")
    p.add_argument("--views", nargs=2, metavar=("VIEW1", "VIEW2"),
                   help="the two dataset views (F maps 1 -> 2); their truth correspondences need the pair in the "
                        "spec's crossview.pairs")
    p.add_argument("--max-matches", type=int, default=20000, help="dataset correspondences sampled (seeded)")
    p.add_argument("--images", nargs=2, metavar=("IMG1", "IMG2"), help="images for the HTML epipolar-line figure")


def score_fmatrix(a):
    F = read_matrix3(a.f_est, key="F")
    F_gt = read_matrix3(a.f_gt, key="F") if a.f_gt else None
    size, images, x1 = (image_size(a.size) if a.size else None), None, None
    pinhole_pair = False
    res, inputs = {}, {"f_est": a.f_est, "matches": a.matches, "f_gt": a.f_gt, "dataset": a.dataset, "views": a.views}
    if a.dataset:
        if not a.views:
            raise InputError("--dataset needs --views VIEW1 VIEW2")
        ds = read_dataset(a.dataset)
        v1, v2 = a.views
        (c1, p1), (c2, p2) = ds.camera(v1), ds.camera(v2)
        rel = p2 @ p1.inverse()  # cam2_from_cam1
        if not a.matches:
            x1, x2 = ds.correspondences(v1, v2, max_points=a.max_matches)
            if len(x1) == 0:
                raise InputError(f"{a.dataset}: views {v1!r} and {v2!r} share no visible truth point")
            inputs["matches"] = f"dataset truth correspondences ({len(x1)} visible, seeded sample)"
        pinhole_pair = c1.model == "pinhole" and c2.model == "pinhole"  # F exists for undistorted pixels only
        if pinhole_pair:
            if F_gt is None:
                F_gt = fundamental(c1.K, c2.K, rel)
                inputs["f_gt"] = "dataset cameras: K2^-T [t]x R K1^-1"
        else:
            inputs["f_gt_note"] = "distorted cameras have no fundamental matrix: no truth F, no pose via K"
        if size is None:
            size = (c1.width, c1.height)
        images = (ds.image(v1), ds.image(v2))
    if x1 is None:
        if not a.matches:
            raise InputError("fmatrix needs --matches M.npy or --dataset DIR --views V1 V2")
        m = read_npy(a.matches, (None, 4))
        x1, x2 = m[:, :2], m[:, 2:]
    res["fundamental"] = fundamental_metrics(F, x1, x2)
    if F_gt is not None:
        if not size:
            raise InputError("--f-gt needs --size W H for Zhang's F-distance")
        res["zhang_f_distance"] = zhang_f_distance(F, F_gt, size)
    if pinhole_pair:
        res["pose_via_K"] = pose_error_from_fundamental(F, c1.K, c2.K, x1, x2, rel.R, rel.t)
    if a.images:
        images = tuple(read_image(p) for p in a.images)
    inputs["size"] = size

    def figures():
        figs = []
        if fundamental_degeneracy(F) is None:
            with np.errstate(invalid="ignore", divide="ignore"):
                s = np.sqrt(sampson_sq_px2(F, x1, x2))
            figs.append(Figure("Cumulative Sampson error", plots.cumulative_figure(
                {"sqrt(Sampson)": np.where(np.isfinite(s), s, np.inf)}, xlabel="Sampson error (px)",
                title="on the truth correspondences", thresholds=(1.0,))))
        if images is not None:
            figs.append(Figure("Epipolar lines", plots.epipolar_figure(images[0], images[1], F, x1, x2, F_gt=F_gt),
                               "16 truth correspondences (seeded)"))
        return figs

    return inputs, res, figures


# --- homography -------------------------------------------------------------------------------
def homography_arguments(p) -> None:
    p.add_argument("h_est", help="estimated H (.txt/.npy/.json)")
    p.add_argument("h_gt", help="truth H (.txt/.npy/.json)")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), required=True)


def score_homography(a):
    W, H = image_size(a.size)
    H_gt = read_matrix3(a.h_gt, key="H")
    if (why := homography_degeneracy(H_gt)) is not None:
        raise InputError(f"{a.h_gt}: the truth H is degenerate ({why})")
    r = homography_mace(read_matrix3(a.h_est, key="H"), H_gt, W, H)
    return ({"h_est": a.h_est, "h_gt": a.h_gt, "size": a.size},
            {"homography": r, "summary": homography_summary([r.mace_px])}, no_figures)


COMMANDS = {"fmatrix": scored(fmatrix_arguments, score_fmatrix),
            "homography": scored(homography_arguments, score_homography)}
