"""``recon-eval``: one subcommand per metric family. Prints a table; ``--json OUT`` writes the
versioned JSON report (see :mod:`recon_eval.report`); ``--html OUT`` a self-contained HTML report
with figures (:mod:`recon_eval.html_report`, needs matplotlib). Bad input -> a message naming the
file and what was expected, exit code 2, no traceback.

Wherever it makes sense the truth may be one of our dataset folders (docs/dataset_format.md):
poses from cameras.json, depth and disparity from the truth EXRs, the GT surface from
scene/meshes, held-out truth points for calibration and PnP, dense visible correspondences and
the truth F for fundamental matrices.

Examples::

    recon-eval cloud REC.ply GT.ply --tau 0.01
    recon-eval cloud REC.ply DATASET_DIR --tau 0.01                   # GT = the dataset's meshes
    recon-eval poses EST_MODEL_DIR GT_MODEL_DIR --alignment sim3     # COLMAP models (bin or txt)
    recon-eval poses EST_MODEL_DIR DATASET_DIR                       # matched by image name = view
    recon-eval poses transforms.json DATASET_DIR                     # NeRF / instant-ngp
    recon-eval poses est_kitti.txt DATASET_DIR --camera cam0         # KITTI: line i = i-th view
    recon-eval poses est_tum.txt gt_tum.txt                          # TUM trajectories
    recon-eval disparity EST.png GT.png --benchmark kitti
    recon-eval disparity EST.pfm DATASET_DIR --view left_000 --benchmark middlebury
    recon-eval depth EST.npy GT.npy --alignment median
    recon-eval depth EST_DIR DATASET_DIR                             # EST_DIR/<view>.npy|.pfm|.exr
    recon-eval fmatrix F_est.txt --matches matches.npy --f-gt F_gt.txt --size 640 480
    recon-eval fmatrix F_est.txt --dataset DATASET_DIR --views cam0_000 cam1_000
    recon-eval homography H_est.txt H_gt.txt --size 640 480
    recon-eval calibration est.yaml DATASET_DIR --view cam0_000
    recon-eval pnp pose.json DATASET_DIR --view cam0_000
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

EXIT_BAD_INPUT = 2
MAP_SUFFIXES = (".npy", ".pfm", ".exr", ".png")


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="recon-eval", description="Score 3D-vision results against exact ground truth.")
    sub = ap.add_subparsers(dest="command", required=True)

    def add(name, help_):
        p = sub.add_parser(name, help=help_, description=help_)
        p.add_argument("--json", metavar="OUT", help="write the JSON report here (atomically)")
        p.add_argument("--html", metavar="OUT", help="write a self-contained HTML report with figures (needs matplotlib)")
        p.add_argument("--quiet", action="store_true", help="do not print the table")
        return p

    p = add("cloud", "point cloud / mesh: Tanks and Temples, ETH3D, DTU, Chamfer")
    p.add_argument("rec", help="reconstruction (.ply/.obj/.stl point cloud or mesh; its vertices are scored)")
    p.add_argument("gt", help="truth (.ply/.obj/.stl, or a dataset folder: its scene meshes); a mesh gives exact "
                              "point-to-triangle distances")
    p.add_argument("--tau", type=float, action="append", help="threshold(s) in metres (default 0.01)")
    p.add_argument("--gt-samples", type=int, default=200_000, help="surface samples of a GT mesh for recall/completeness")
    p.add_argument("--seed", type=int, default=0, help="seed of the GT mesh surface sample")
    p.add_argument("--no-downsample", action="store_true", help="skip Tanks and Temples' tau/2 voxel downsampling")
    p.add_argument("--eth3d-voxel", type=float, default=0.01, help="ETH3D per-voxel averaging size, metres")
    p.add_argument("--dtu-max-dist", type=float, default=0.02, help="DTU outlier cut, metres")

    p = add("poses", "camera poses: APE, RPE, registration ratio, relative-pose AUC and mAA")
    p.add_argument("est", help="COLMAP model dir, NeRF transforms.json, TUM or KITTI odometry trajectory, or a dataset")
    p.add_argument("gt", help="dataset folder (cameras.json), COLMAP model dir, transforms.json, TUM or KITTI file")
    p.add_argument("--alignment", choices=["none", "se3", "sim3"], default="sim3")
    p.add_argument("--delta", type=int, default=1, help="RPE frame offset")
    p.add_argument("--max-time-diff", type=float, default=0.01, help="TUM timestamp association, seconds")
    p.add_argument("--camera", help="dataset truth: only the views of this spec camera (e.g. the left camera of a "
                                    "KITTI-style trajectory)")
    p.add_argument("--kitti-convention", choices=["world_from_cam", "cam_from_world"], default="world_from_cam",
                   help="what a KITTI line holds (KITTI odometry: world_from_cam of the left camera)")

    p = add("disparity", "stereo disparity: KITTI D1, Middlebury, ETH3D two-view")
    p.add_argument("est", help="estimated disparity (.png KITTI uint16, .pfm, .npy, .exr)")
    p.add_argument("gt", help="truth disparity (occ / all pixels), or a dataset folder with --view")
    p.add_argument("--view", help="dataset truth: the left view of a rectified stereo pair")
    p.add_argument("--right-view", help="dataset truth: its right view (default: the other member of the rig)")
    p.add_argument("--gt-noc", help="non-occluded truth (KITTI) or non-occlusion mask source (.png/.pfm/.npy/.exr)")
    p.add_argument("--obj-map", help="KITTI foreground map PNG")
    p.add_argument("--benchmark", choices=["kitti", "middlebury", "eth3d"], default="kitti")

    p = add("depth", "depth maps: Eigen abs_rel, sq_rel, rmse, rmse_log, a1..a3")
    p.add_argument("est", help="predicted z-depth (.npy, .pfm, .exr), metres; with a dataset truth also a folder "
                               "of <view>.npy|.pfm|.exr (a view without a file is a failed image)")
    p.add_argument("gt", help="truth depth (.npy, .pfm, .exr), metres, or a dataset folder (truth/<view>.exr depth_z)")
    p.add_argument("--view", action="append", help="dataset truth: view(s) to score (default: all; a single "
                                                   "estimate file needs exactly one)")
    p.add_argument("--alignment", choices=["none", "median", "scale_shift"], default="none")
    p.add_argument("--min-depth", type=float, default=0.0)
    p.add_argument("--max-depth", type=float, default=float("inf"))

    p = add("fmatrix", "fundamental matrix: Sampson, symmetric epipolar, Zhang distance, pose via K")
    p.add_argument("f_est", help="estimated F (.txt/.npy/.json)")
    p.add_argument("--matches", help="truth correspondences .npy (N, 4): x1 y1 x2 y2, OpenCV pixels")
    p.add_argument("--f-gt", help="truth F for Zhang's F-distance")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), help="image size for Zhang's F-distance")
    p.add_argument("--dataset", help="dataset folder: truth F, correspondences, K, size and images of --views")
    p.add_argument("--views", nargs=2, metavar=("VIEW1", "VIEW2"), help="the two dataset views (F maps 1 -> 2)")
    p.add_argument("--max-matches", type=int, default=20000, help="dataset correspondences sampled (seeded)")
    p.add_argument("--images", nargs=2, metavar=("IMG1", "IMG2"), help="images for the HTML epipolar-line figure")

    p = add("homography", "homography: mean corner error, accuracy and AUC")
    p.add_argument("h_est", help="estimated H (.txt/.npy/.json)")
    p.add_argument("h_gt", help="truth H (.txt/.npy/.json)")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), required=True)

    p = add("calibration", "intrinsics: fx/fy/cx/cy errors, projection difference field, reprojection RMS")
    p.add_argument("est", help="estimated calibration, OpenCV YAML/JSON (camera_matrix/K, distortion_coefficients/D)")
    p.add_argument("gt", help="truth: a dataset folder (camera of --view) or an OpenCV YAML/JSON calibration")
    p.add_argument("--view", help="dataset truth: the view whose camera is the truth (default: the first view)")
    p.add_argument("--est-model", choices=["opencv", "fisheye"], help="override the estimate's distortion model")
    p.add_argument("--grid", type=int, nargs=2, default=(60, 40), metavar=("NX", "NY"), help="projection-difference grid")
    p.add_argument("--points", type=int, default=5000, help="dataset truth: held-out truth points for reprojection")

    p = add("pnp", "absolute pose: rotation angle, translation error, reprojection RMS")
    p.add_argument("est", help="estimated pose (.json {R, t} / 3x4 / 4x4, .npy, .txt)")
    p.add_argument("gt", help="truth: a dataset folder (pose of --view) or a pose file")
    p.add_argument("--view", help="dataset truth: the view (required when the dataset has several)")
    p.add_argument("--est-convention", choices=["cam_from_world", "world_from_cam"], default="cam_from_world",
                   help="what a bare matrix in EST holds (default: OpenCV solvePnP's cam_from_world)")
    p.add_argument("--gt-convention", choices=["cam_from_world", "world_from_cam"], default="cam_from_world")
    p.add_argument("--points", type=int, default=5000, help="dataset truth: held-out truth points for reprojection")
    p.add_argument("--points-world", help="non-dataset truth: (N, 3) .npy world points for reprojection")
    p.add_argument("--pixels", help="non-dataset truth: (N, 2) .npy pixels observing them")
    p.add_argument("--calib", help="non-dataset truth: camera for reprojection (OpenCV YAML/JSON)")
    from recon_eval import cli_features, cli_geometry
    from recon_eval.cli_tools import add_parsers  # run, leaderboard, gate (docs/ci.md)

    cli_features.add_parsers(add)  # features (docs/features.md)
    cli_geometry.add_parsers(add)  # dlt, triangulation
    add_parsers(sub)
    return ap


def _no_figures():
    return []


def _is_dataset(path) -> bool:
    from recon_eval.readers.scenegen_dataset import is_dataset

    return is_dataset(path)


def _read_map(path: str, kind: str = "depth"):
    from recon_eval.errors import InputError

    suffix = Path(path).suffix.lower()
    if suffix == ".png":
        from recon_eval.readers.kitti_png import read_kitti_disparity

        return read_kitti_disparity(path)
    if suffix == ".pfm":
        from recon_eval.readers.pfm import read_pfm

        return read_pfm(path)
    if suffix == ".npy":
        from recon_eval.readers.npy import read_npy

        return read_npy(path, (None, None))
    if suffix == ".exr":
        from recon_eval.readers.exr import read_exr_map

        return read_exr_map(path, kind=kind)
    if Path(path).is_dir():
        raise InputError(f"{path}: is a folder, expected an image file (.png, .pfm, .npy or .exr)")
    raise InputError(f"{path}: unknown image format {suffix!r} (expected .png, .pfm, .npy or .exr)")


def _same_shape(est, gt, est_name, gt_name) -> None:
    from recon_eval.errors import InputError

    if est.shape != gt.shape:
        raise InputError(f"{est_name}: shape {est.shape} differs from the truth's {gt.shape} ({gt_name})")


def _dataset_view(ds, view, where: str) -> str:
    from recon_eval.errors import InputError

    if view is None:
        if len(ds.views) != 1:
            raise InputError(f"{ds.root}: {where} needs --view VIEW (complete views: {', '.join(ds.views[:8])}"
                             f"{' ...' if len(ds.views) > 8 else ''})")
        return ds.views[0]
    ds._check_view(view)
    return view


# --- cloud ------------------------------------------------------------------------------------
def _cmd_cloud(a):
    from recon_eval.distances import sample_mesh_surface
    from recon_eval.pointcloud import chamfer, dtu, eth3d, tanks_and_temples, tanks_and_temples_distances
    from recon_eval.readers.ply import read_geometry

    rec = read_geometry(a.rec)
    gt_kind = "file"
    if _is_dataset(a.gt):
        from recon_eval.readers.scenegen_dataset import read_dataset

        V, F = read_dataset(a.gt).mesh()
        gt_kind = "scenegen-dataset scene/meshes"
    else:
        g = read_geometry(a.gt)
        V, F = g.vertices, g.faces
    mesh = None
    gt_pts = V
    if F is not None and len(F):
        mesh = (V, F)
        gt_pts = sample_mesh_surface(V, F, a.gt_samples, seed=a.seed)
    taus = a.tau or [0.01]
    res = {}
    for tau in taus:
        res[f"tanks_and_temples@{tau:g}m"] = tanks_and_temples(rec.vertices, gt_pts, tau, gt_mesh=mesh,
                                                              downsample=not a.no_downsample)
        res[f"eth3d@{tau:g}m"] = eth3d(rec.vertices, gt_pts, tau, gt_mesh=mesh, voxel_m=a.eth3d_voxel)
    res["dtu"] = dtu(rec.vertices, gt_pts, max_dist_m=a.dtu_max_dist, gt_mesh=mesh)
    res["chamfer"] = chamfer(rec.vertices, gt_pts, gt_mesh=mesh)
    inputs = {"rec": a.rec, "gt": a.gt, "gt_kind": gt_kind, "gt_is_mesh": mesh is not None,
              "gt_points": "mesh surface sample" if mesh is not None else "file vertices",
              "gt_samples": a.gt_samples if mesh is not None else None, "seed": a.seed, "tau_m": taus}

    def figures():
        import numpy as np

        from recon_eval import plots
        from recon_eval.html_report import Figure

        tau = taus[0]
        d_rg, d_gr, _, _ = tanks_and_temples_distances(rec.vertices, gt_pts, tau, gt_mesh=mesh,
                                                       downsample=not a.no_downsample)
        ts = np.linspace(0.0, 5.0 * max(taus), 201)[1:]
        return [
            Figure("Precision / recall / F-score vs tau",
                   plots.precision_recall_figure(d_rg, d_gr, ts, tau_m=tau, title="Tanks and Temples, strict <"),
                   f"distances after voxel downsampling at {tau:g}/2 m, as the Tanks and Temples toolbox plots them"),
            Figure("Cumulative distances",
                   plots.cumulative_figure({"rec -> GT (precision side)": d_rg, "GT -> rec (recall side)": d_gr},
                                           xlabel="distance (m)", title="cumulative distance distribution",
                                           thresholds=taus, xmax=5.0 * max(taus))),
        ]

    return inputs, res, figures


# --- poses ------------------------------------------------------------------------------------
def _sniff_trajectory(path: Path) -> str:
    """'tum' (8 numbers per line) or 'kitti' (12)."""
    from recon_eval.errors import InputError
    from recon_eval.readers._text import read_text

    for ln in read_text(path, "a TUM or KITTI trajectory").splitlines():
        ln = ln.split("#", 1)[0].replace(",", " ").strip()
        if ln:
            n = len(ln.split())
            if n in (8, 12):
                return "tum" if n == 8 else "kitti"
            raise InputError(f"{path}:1: expected 8 (TUM) or 12 (KITTI odometry) numbers per line, got {n}")
    raise InputError(f"{path}: empty trajectory (expected TUM or KITTI lines)")


def _read_poses(path: str, a):
    """(kind, Poses or TumTrajectory) for any supported pose source."""
    from recon_eval.errors import InputError

    p = Path(path)
    if _is_dataset(p):
        from recon_eval.readers.scenegen_dataset import read_dataset

        ds = read_dataset(p)
        poses = ds.poses
        if a.camera:
            keep = ds.views_of_camera(a.camera)
            if not keep:
                raise InputError(f"{p / 'cameras.json'}: camera_name: no complete view of camera {a.camera!r}")
            poses = _subset(poses, keep)
        return "dataset", poses
    if p.is_dir():
        from recon_eval.readers.colmap_binary import read_colmap_binary
        from recon_eval.readers.colmap_text import read_colmap_text

        if (p / "images.bin").is_file():
            return "colmap", read_colmap_binary(p).poses
        if (p / "images.txt").is_file():
            return "colmap", read_colmap_text(p).poses
        raise InputError(f"{p}: folder is neither a dataset (manifest.json, cameras.json) nor a COLMAP model "
                         "(images.bin or images.txt)")
    if not p.is_file():
        raise InputError(f"{p}: no such file or folder (expected poses: dataset, COLMAP model, transforms.json, "
                         "TUM or KITTI trajectory)")
    if p.suffix.lower() == ".json":
        from recon_eval.readers.nerf import read_nerf_transforms

        return "nerf", read_nerf_transforms(p).poses
    if _sniff_trajectory(p) == "tum":
        from recon_eval.readers.tum import read_tum

        return "tum", read_tum(p)
    from recon_eval.readers.kitti_odometry import read_kitti_poses

    return "kitti", read_kitti_poses(p, a.kitti_convention)


def _subset(poses, names):
    from recon_eval.poses import Poses

    idx = [poses.names.index(n) for n in names]
    return Poses(tuple(names), poses.R_cam_from_world[idx], poses.t_cam_from_world[idx])


def _match_names_by_stem(est, gt):
    """Rename estimated poses whose name is not a truth name but whose file name, or file name
    without its extension, is (COLMAP ``images/cam0_000.png`` -> view ``cam0_000``)."""
    from pathlib import PurePosixPath

    from recon_eval.poses import Poses

    truth, names, renamed = set(gt.names), [], False
    for n in est.names:
        if n not in truth:
            base = PurePosixPath(n.replace("\\", "/")).name
            for cand in (base, base.rsplit(".", 1)[0]):
                if cand in truth:
                    n, renamed = cand, True
                    break
        names.append(n)
    return (Poses(tuple(names), est.R_cam_from_world, est.t_cam_from_world) if renamed else est), renamed


def _cmd_poses(a):
    from recon_eval.align import Alignment
    from recon_eval.errors import InputError
    from recon_eval.poses import Poses, ape, relative_pose, rpe

    ek, est = _read_poses(a.est, a)
    gk, gt = _read_poses(a.gt, a)
    matching = "by name"
    if (ek == "tum") != (gk == "tum"):
        raise InputError(f"{a.est if ek == 'tum' else a.gt}: a TUM trajectory is matched by timestamps and needs a "
                         "TUM trajectory on the other side")
    if ek == "tum":
        from recon_eval.readers.tum import associate

        est, gt = associate(est, gt, a.max_time_diff), gt.poses
        matching = f"TUM timestamps within {a.max_time_diff} s"
    elif ek == "kitti" and gk != "kitti":
        # KITTI lines carry no names: line i is the i-th truth pose in truth order
        n = min(len(est.names), len(gt.names))  # lines beyond the truth keep their own names: n_extra
        est = Poses(gt.names[:n] + est.names[n:], est.R_cam_from_world, est.t_cam_from_world)
        matching = "KITTI line i = i-th truth view"
    else:
        est, renamed = _match_names_by_stem(est, gt)
        if renamed:
            matching = "by name (folders and image extensions ignored where needed)"
    if len(gt.names) == 0:
        raise InputError(f"{a.gt}: the truth has no poses")
    al = Alignment(a.alignment)
    res = {"ape": ape(est, gt, alignment=al), "rpe": rpe(est, gt, delta_frames=a.delta, alignment=al),
           "relative_pose": relative_pose(est, gt)}
    inputs = {"est": a.est, "gt": a.gt, "format": ek, "gt_format": gk, "matching": matching,
              "alignment": a.alignment, "delta_frames": a.delta, "camera": a.camera,
              "kitti_convention": a.kitti_convention if "kitti" in (ek, gk) else None}

    def figures():
        from recon_eval import plots
        from recon_eval.html_report import Figure

        r, rp = res["ape"], res["relative_pose"]
        return [
            Figure("Per-camera pose errors", plots.per_camera_figure(r.names, r.trans_err_m, r.rot_err_deg,
                                                                     title=f"APE after {a.alignment} alignment")),
            Figure("Cumulative APE", plots.cumulative_figure({"rotation (deg)": r.rot_err_deg},
                                                             xlabel="rotation error (deg)", title="APE rotation")),
            Figure("Cumulative APE translation", plots.cumulative_figure({"translation (m)": r.trans_err_m},
                                                                         xlabel="translation error (m)",
                                                                         title="APE translation")),
            Figure("Cumulative relative pose error",
                   plots.cumulative_figure({"max(rot, trans dir)": rp.pose_err_deg}, xlabel="pose error (deg)",
                                           title="relative pose (AUC thresholds 5/10/20 deg)",
                                           thresholds=(5.0, 10.0, 20.0), xmax=30.0)),
        ]

    return inputs, res, figures


# --- disparity --------------------------------------------------------------------------------
def _cmd_disparity(a):
    import numpy as np

    from recon_eval.errors import InputError
    from recon_eval.stereo import eth3d_two_view, kitti_d1, middlebury

    est = _read_map(a.est, "disparity")
    gt_kind = "file"
    if _is_dataset(a.gt):
        from recon_eval.readers.scenegen_dataset import read_dataset

        ds = read_dataset(a.gt)
        view = _dataset_view(ds, a.view, "a disparity truth")
        gt = ds.disparity(view, a.right_view)
        gt_kind = f"scenegen-dataset view {view}: fx * baseline / depth_z"
    else:
        if a.view:
            raise InputError(f"--view needs a dataset truth; {a.gt} is not a dataset folder")
        gt = _read_map(a.gt, "disparity")
    _same_shape(est, gt, a.est, a.gt)
    noc = _read_map(a.gt_noc, "disparity") if a.gt_noc else None
    if a.benchmark == "kitti":
        obj = None
        if a.obj_map:
            from recon_eval.readers.kitti_png import read_kitti_obj_map

            obj = [read_kitti_obj_map(a.obj_map)]
        res = {"kitti_d1": kitti_d1([est], [gt], None if noc is None else [noc], obj)}
    else:
        mask = None if noc is None else np.isfinite(noc)
        fn = middlebury if a.benchmark == "middlebury" else eth3d_two_view
        res = {a.benchmark: fn(est, gt, mask)}
    inputs = {"est": a.est, "gt": a.gt, "gt_kind": gt_kind, "gt_noc": a.gt_noc, "obj_map": a.obj_map,
              "benchmark": a.benchmark}

    def figures():
        from recon_eval import plots
        from recon_eval.html_report import Figure

        e = np.abs(est - gt)
        e = e[np.isfinite(gt)]
        return [
            Figure("Disparity error", plots.map_error_figure(est, gt, title="disparity", unit="px", error_clip=6.0),
                   "error colour scale capped at 6 px (twice KITTI's 3 px)"),
            Figure("Cumulative disparity error",
                   plots.cumulative_figure({"|d - d*| over truth pixels": e}, xlabel="disparity error (px)",
                                           title="cumulative error (missing estimates count as failures)",
                                           thresholds=(0.5, 1.0, 2.0, 3.0, 4.0), xmax=8.0)),
        ]

    return inputs, res, figures


# --- depth ------------------------------------------------------------------------------------
def _cmd_depth(a):
    import numpy as np

    from recon_eval.depth import eigen_depth_metrics
    from recon_eval.errors import InputError

    names = None
    if _is_dataset(a.gt):
        from recon_eval.readers.scenegen_dataset import read_dataset

        ds = read_dataset(a.gt)
        if Path(a.est).is_dir():
            views = a.view or list(ds.views)
            for v in views:
                ds._check_view(v)
            est_list, missing = [], []
            gt_list = [ds.depth(v) for v in views]
            for v, g in zip(views, gt_list):
                f = next((Path(a.est) / (v + s) for s in MAP_SUFFIXES[:3] if (Path(a.est) / (v + s)).is_file()), None)
                if f is None:
                    missing.append(v)
                    est_list.append(np.full_like(g, np.nan))
                else:
                    est_list.append(_read_map(str(f), "depth"))
                    _same_shape(est_list[-1], g, f, f"{a.gt} view {v}")
            names = list(views)
        else:
            if a.view and len(a.view) > 1:
                raise InputError(f"{a.est}: one estimate file scores one view; pass a folder of <view> files for several")
            v = _dataset_view(ds, a.view[0] if a.view else None, "a single depth estimate")
            est_list, gt_list, missing, names = [_read_map(a.est, "depth")], [ds.depth(v)], [], [v]
            _same_shape(est_list[0], gt_list[0], a.est, f"{a.gt} view {v}")
        gt_kind = "scenegen-dataset truth/<view>.exr depth_z"
    else:
        if a.view:
            raise InputError(f"--view needs a dataset truth; {a.gt} is not a dataset folder")
        est_list, gt_list, missing, gt_kind = [_read_map(a.est, "depth")], [_read_map(a.gt, "depth")], [], "file"
        _same_shape(est_list[0], gt_list[0], a.est, a.gt)
    res = {"eigen": eigen_depth_metrics(est_list, gt_list, alignment=a.alignment,
                                        min_depth_m=a.min_depth, max_depth_m=a.max_depth)}
    inputs = {"est": a.est, "gt": a.gt, "gt_kind": gt_kind, "views": names, "views_without_estimate": missing,
              "alignment": a.alignment}

    def figures():
        from recon_eval import plots
        from recon_eval.html_report import Figure

        r = res["eigen"]
        figs, rel = [], {}
        for k, (e, g) in enumerate(zip(est_list, gt_list)):
            e_al = r.per_image_scale[k] * e + r.per_image_shift_m[k]
            label = names[k] if names else Path(a.est).name
            if k < 8:
                figs.append(Figure(f"Depth error: {label}",
                                   plots.map_error_figure(e_al, g, title=f"{label} (alignment {a.alignment})", unit="m")))
            with np.errstate(invalid="ignore", divide="ignore"):
                ok = np.isfinite(g) & (g > a.min_depth) & (g < a.max_depth)
                rel[label] = np.where(np.isfinite(e_al[ok]) & (e_al[ok] > 0), np.abs(e_al[ok] - g[ok]) / g[ok], np.inf)
        if len(rel) > 6:
            rel = {"all images": np.concatenate(list(rel.values()))}
        figs.append(Figure("Cumulative relative depth error",
                           plots.cumulative_figure(rel, xlabel="|p - g| / g", title="cumulative abs_rel per pixel",
                                                   thresholds=(0.25,), xmax=0.5),
                           "missing predictions count as failures; 0.25 = a1's ratio bound"))
        return figs

    return inputs, res, figures


# --- fundamental matrix -----------------------------------------------------------------------
def _cmd_fmatrix(a):
    import numpy as np

    from recon_eval.epipolar import (fundamental_from_pose, fundamental_metrics, pose_error_from_fundamental,
                                     zhang_f_distance)
    from recon_eval.errors import InputError
    from recon_eval.readers.matrix import read_matrix3
    from recon_eval.readers.npy import read_npy

    F = read_matrix3(a.f_est, key="F")
    F_gt = read_matrix3(a.f_gt, key="F") if a.f_gt else None
    size, images, x1 = (tuple(a.size) if a.size else None), None, None
    res, inputs = {}, {"f_est": a.f_est, "matches": a.matches, "f_gt": a.f_gt, "dataset": a.dataset, "views": a.views}
    if a.dataset:
        from recon_eval.readers.scenegen_dataset import read_dataset

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
        if c1.model == "pinhole" and c2.model == "pinhole":
            if F_gt is None:
                F_gt = fundamental_from_pose(c1.K, c2.K, rel.R, rel.t)
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
    if a.dataset and c1.model == "pinhole" and c2.model == "pinhole":
        res["pose_via_K"] = pose_error_from_fundamental(F, c1.K, c2.K, x1, x2, rel.R, rel.t)
    if a.images:
        images = tuple(_read_image(p) for p in a.images)
    inputs["size"] = size

    def figures():
        from recon_eval import plots
        from recon_eval.epipolar import fundamental_degeneracy, sampson_sq_px2
        from recon_eval.html_report import Figure

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


def _read_image(path: str):
    import cv2

    from recon_eval.errors import InputError

    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED) if Path(path).is_file() else None
    if img is None:
        raise InputError(f"{path}: cannot read as an image (expected PNG/JPEG)")
    return img[..., ::-1] if img.ndim == 3 else img


# --- homography -------------------------------------------------------------------------------
def _cmd_homography(a):
    from recon_eval.epipolar import homography_mace, homography_summary
    from recon_eval.readers.matrix import read_matrix3

    r = homography_mace(read_matrix3(a.h_est, key="H"), read_matrix3(a.h_gt, key="H"), *a.size)
    return ({"h_est": a.h_est, "h_gt": a.h_gt, "size": a.size},
            {"homography": r, "summary": homography_summary([r.mace_px])}, _no_figures)


# --- calibration ------------------------------------------------------------------------------
def _cmd_calibration(a):
    from recon_eval.calibration import intrinsics_errors, projection_difference, reprojection_rms
    from recon_eval.errors import InputError
    from recon_eval.readers.opencv_calib import read_opencv_calibration

    est = read_opencv_calibration(a.est, model=a.est_model)
    inputs = {"est": a.est, "gt": a.gt, "est_model": est.model}
    rep = None
    if _is_dataset(a.gt):
        from recon_eval.readers.scenegen_dataset import read_dataset

        ds = read_dataset(a.gt)
        view = a.view or ds.views[0]
        gt, pose = ds.camera(view)
        uv, X = ds.points_at_pixels(view, max_points=a.points)
        inputs.update(view=view, gt_kind="scenegen-dataset camera", held_out_points=len(X))
    else:
        if a.view:
            raise InputError(f"--view needs a dataset truth; {a.gt} is not a dataset folder")
        gt = read_opencv_calibration(a.gt)
        inputs["gt_kind"] = "OpenCV calibration file"
    inputs["gt_model"] = gt.model
    if (gt.width, gt.height) != (est.width, est.height):
        raise InputError(f"{a.est}: image_width/image_height {est.width}x{est.height} differ from the truth's "
                         f"{gt.width}x{gt.height} ({a.gt})")
    nx, ny = a.grid
    res = {"intrinsics": intrinsics_errors(est.K, gt.K),
           "projection_diff": projection_difference(gt, est, grid_nx=nx, grid_ny=ny),
           "projection_diff_rotation_fitted": projection_difference(gt, est, grid_nx=nx, grid_ny=ny, fit_rotation=True)}
    if _is_dataset(a.gt):
        rep = reprojection_rms(est, pose.R, pose.t, X, uv)
        res["reprojection_held_out"] = rep

    def figures():
        from recon_eval import plots
        from recon_eval.html_report import Figure

        figs = []
        for key, what in (("projection_diff", "intrinsics only"), ("projection_diff_rotation_fitted", "rotation fitted")):
            r = res[key]
            figs.append(Figure(f"Projection difference ({what})",
                               plots.field_figure(r.diff_px, r.grid_u_px, r.grid_v_px, unit="px",
                                                  title=f"|project_est(unproject_gt(x)) - x|, {what}"),
                               f"mrcal-style; mean {r.mean_px:.4g} px, max {r.max_px:.4g} px"))
        return figs

    return inputs, res, figures


# --- PnP --------------------------------------------------------------------------------------
def _cmd_pnp(a):
    from recon_eval.errors import InputError
    from recon_eval.pnp import pnp_errors
    from recon_eval.readers.pose_file import read_pose

    R_est, t_est = read_pose(a.est, a.est_convention)
    inputs = {"est": a.est, "gt": a.gt, "est_convention": a.est_convention}
    cam = X = uv = None
    if _is_dataset(a.gt):
        from recon_eval.readers.scenegen_dataset import read_dataset

        ds = read_dataset(a.gt)
        view = _dataset_view(ds, a.view, "a PnP truth")
        cam, pose = ds.camera(view)
        R_gt, t_gt = pose.R, pose.t
        uv, X = ds.points_at_pixels(view, max_points=a.points)
        inputs.update(view=view, gt_kind="scenegen-dataset cameras.json", held_out_points=len(X))
    else:
        if a.view:
            raise InputError(f"--view needs a dataset truth; {a.gt} is not a dataset folder")
        import numpy as np

        R_gt, t_gt = read_pose(a.gt, a.gt_convention)
        if not (np.all(np.isfinite(R_gt)) and np.all(np.isfinite(t_gt))):
            raise InputError(f"{a.gt}: the truth pose has non-finite values")
        inputs.update(gt_kind="pose file", gt_convention=a.gt_convention)
        if a.points_world or a.pixels or a.calib:
            if not (a.points_world and a.pixels and a.calib):
                raise InputError("reprojection needs all of --points-world, --pixels and --calib")
            from recon_eval.readers.npy import read_npy
            from recon_eval.readers.opencv_calib import read_opencv_calibration

            X, uv, cam = read_npy(a.points_world, (None, 3)), read_npy(a.pixels, (None, 2)), read_opencv_calibration(a.calib)
            if len(X) != len(uv):
                raise InputError(f"{a.points_world} ({len(X)} points) and {a.pixels} ({len(uv)} pixels) differ in length")
    return inputs, {"pnp": pnp_errors(R_est, t_est, R_gt, t_gt, cam=cam, points_world=X, pixels=uv)}, _no_figures


_COMMANDS = {"cloud": _cmd_cloud, "poses": _cmd_poses, "disparity": _cmd_disparity, "depth": _cmd_depth,
             "fmatrix": _cmd_fmatrix, "homography": _cmd_homography, "calibration": _cmd_calibration,
             "pnp": _cmd_pnp}


def _commands() -> dict:
    from recon_eval import cli_features, cli_geometry

    return {**_COMMANDS, **cli_features.COMMANDS, **cli_geometry.COMMANDS}


def main(argv=None) -> int:
    args = _parser().parse_args(argv)  # argparse itself exits with code 2 on bad usage
    from recon_eval import cli_tools

    if args.command in cli_tools.COMMANDS:
        return cli_tools.handle(args)
    from recon_eval.errors import InputError
    from recon_eval.report import document, print_table, write_json_atomic

    try:
        inputs, results, figures = _commands()[args.command](args)
        if not args.quiet:
            print_table(f"recon-eval {args.command}", results)
        if args.json:
            write_json_atomic(args.json, document(args.command, inputs, results))
        if args.html:
            try:
                import matplotlib  # noqa: F401
            except ImportError:
                raise InputError("--html needs matplotlib (pip install matplotlib)") from None
            from recon_eval.html_report import render_html, write_html_atomic

            write_html_atomic(args.html, render_html(args.command, inputs, results, figures()))
    except InputError as exc:
        print(f"recon-eval: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:  # unreadable input or unwritable output
        print(f"recon-eval: error: {exc.filename or ''}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0


if __name__ == "__main__":
    sys.exit(main())
