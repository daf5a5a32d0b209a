"""``recon-eval``: one subcommand per metric family. Prints a table; ``--json OUT`` writes the
versioned JSON report (see :mod:`recon_eval.report`). Bad input -> a message naming the file and
what was expected, exit code 2, no traceback.

Examples::

    recon-eval cloud REC.ply GT.ply --tau 0.01
    recon-eval poses EST_MODEL_DIR GT_MODEL_DIR --alignment sim3     # COLMAP models (bin or txt)
    recon-eval poses est_tum.txt gt_tum.txt                          # TUM trajectories
    recon-eval disparity EST.png GT.png --benchmark kitti
    recon-eval depth EST.npy GT.npy --alignment median
    recon-eval fmatrix F_est.txt --matches matches.npy --f-gt F_gt.txt --size 640 480
    recon-eval homography H_est.txt H_gt.txt --size 640 480
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

EXIT_BAD_INPUT = 2


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="recon-eval", description="Score 3D-vision results against exact ground truth.")
    sub = ap.add_subparsers(dest="command", required=True)

    def add(name, help_):
        p = sub.add_parser(name, help=help_, description=help_)
        p.add_argument("--json", metavar="OUT", help="write the JSON report here (atomically)")
        p.add_argument("--quiet", action="store_true", help="do not print the table")
        return p

    p = add("cloud", "point cloud / mesh: Tanks and Temples, ETH3D, DTU, Chamfer")
    p.add_argument("rec", help="reconstruction (.ply/.obj/.stl point cloud or mesh; its vertices are scored)")
    p.add_argument("gt", help="truth (.ply/.obj/.stl); a mesh gives exact point-to-triangle distances")
    p.add_argument("--tau", type=float, action="append", help="threshold(s) in metres (default 0.01)")
    p.add_argument("--gt-samples", type=int, default=200_000, help="surface samples of a GT mesh for recall/completeness")
    p.add_argument("--seed", type=int, default=0, help="seed of the GT mesh surface sample")
    p.add_argument("--no-downsample", action="store_true", help="skip Tanks and Temples' tau/2 voxel downsampling")
    p.add_argument("--eth3d-voxel", type=float, default=0.01, help="ETH3D per-voxel averaging size, metres")
    p.add_argument("--dtu-max-dist", type=float, default=0.02, help="DTU outlier cut, metres")

    p = add("poses", "camera poses: APE, RPE, registration ratio, relative-pose AUC and mAA")
    p.add_argument("est", help="COLMAP model directory (binary or text) or TUM trajectory file")
    p.add_argument("gt", help="COLMAP model directory (binary or text) or TUM trajectory file (same kind as est)")
    p.add_argument("--alignment", choices=["none", "se3", "sim3"], default="sim3")
    p.add_argument("--delta", type=int, default=1, help="RPE frame offset")
    p.add_argument("--max-time-diff", type=float, default=0.01, help="TUM timestamp association, seconds")

    p = add("disparity", "stereo disparity: KITTI D1, Middlebury, ETH3D two-view")
    p.add_argument("est", help="estimated disparity (.png KITTI uint16, .pfm, .npy)")
    p.add_argument("gt", help="truth disparity (occ / all pixels)")
    p.add_argument("--gt-noc", help="non-occluded truth (KITTI) or non-occlusion mask source (.png/.pfm/.npy)")
    p.add_argument("--obj-map", help="KITTI foreground map PNG")
    p.add_argument("--benchmark", choices=["kitti", "middlebury", "eth3d"], default="kitti")

    p = add("depth", "depth maps: Eigen abs_rel, sq_rel, rmse, rmse_log, a1..a3")
    p.add_argument("est", help="predicted depth (.npy, .pfm), metres")
    p.add_argument("gt", help="truth depth (.npy, .pfm), metres")
    p.add_argument("--alignment", choices=["none", "median", "scale_shift"], default="none")
    p.add_argument("--min-depth", type=float, default=0.0)
    p.add_argument("--max-depth", type=float, default=float("inf"))

    p = add("fmatrix", "fundamental matrix: Sampson, symmetric epipolar, Zhang distance")
    p.add_argument("f_est", help="estimated F (.txt/.npy/.json)")
    p.add_argument("--matches", required=True, help="truth correspondences .npy (N, 4): x1 y1 x2 y2, OpenCV pixels")
    p.add_argument("--f-gt", help="truth F for Zhang's F-distance")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), help="image size for Zhang's F-distance")

    p = add("homography", "homography: mean corner error, accuracy and AUC")
    p.add_argument("h_est", help="estimated H (.txt/.npy/.json)")
    p.add_argument("h_gt", help="truth H (.txt/.npy/.json)")
    p.add_argument("--size", type=int, nargs=2, metavar=("W", "H"), required=True)
    return ap


def _read_map(path: str):
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
    raise InputError(f"{path}: unknown image format {suffix!r} (expected .png, .pfm or .npy)")


def _cmd_cloud(a):
    from recon_eval.distances import sample_mesh_surface
    from recon_eval.pointcloud import chamfer, dtu, eth3d, tanks_and_temples
    from recon_eval.readers.ply import read_geometry

    rec = read_geometry(a.rec)
    gt = read_geometry(a.gt)
    mesh = None
    gt_pts = gt.vertices
    if gt.faces is not None:
        mesh = (gt.vertices, gt.faces)
        gt_pts = sample_mesh_surface(gt.vertices, gt.faces, a.gt_samples, seed=a.seed)
    taus = a.tau or [0.01]
    res = {}
    for tau in taus:
        res[f"tanks_and_temples@{tau:g}m"] = tanks_and_temples(rec.vertices, gt_pts, tau, gt_mesh=mesh,
                                                              downsample=not a.no_downsample)
        res[f"eth3d@{tau:g}m"] = eth3d(rec.vertices, gt_pts, tau, gt_mesh=mesh, voxel_m=a.eth3d_voxel)
    res["dtu"] = dtu(rec.vertices, gt_pts, max_dist_m=a.dtu_max_dist, gt_mesh=mesh)
    res["chamfer"] = chamfer(rec.vertices, gt_pts, gt_mesh=mesh)
    inputs = {"rec": a.rec, "gt": a.gt, "gt_is_mesh": mesh is not None,
              "gt_points": "mesh surface sample" if mesh is not None else "file vertices",
              "gt_samples": a.gt_samples if mesh is not None else None, "seed": a.seed, "tau_m": taus}
    return inputs, res


def _cmd_poses(a):
    from recon_eval.align import Alignment
    from recon_eval.errors import InputError
    from recon_eval.poses import ape, relative_pose, rpe

    e, g = Path(a.est), Path(a.gt)
    if e.is_dir() != g.is_dir():
        raise InputError(f"{a.est} and {a.gt}: expected two COLMAP model directories or two TUM files")
    if g.is_dir():
        from recon_eval.readers.colmap_binary import read_colmap_binary
        from recon_eval.readers.colmap_text import read_colmap_text

        def read(d: Path):
            return (read_colmap_binary(d) if (d / "images.bin").is_file() else read_colmap_text(d)).poses

        est, gt = read(e), read(g)
        kind = "colmap"
    else:
        from recon_eval.readers.tum import associate, read_tum

        tg = read_tum(g)
        est, gt = associate(read_tum(e), tg, a.max_time_diff), tg.poses
        kind = "tum"
    if len(gt.names) == 0:
        raise InputError(f"{a.gt}: the truth has no poses")
    al = Alignment(a.alignment)
    res = {"ape": ape(est, gt, alignment=al), "rpe": rpe(est, gt, delta_frames=a.delta, alignment=al),
           "relative_pose": relative_pose(est, gt)}
    return {"est": a.est, "gt": a.gt, "format": kind, "alignment": a.alignment, "delta_frames": a.delta}, res


def _cmd_disparity(a):
    import numpy as np

    from recon_eval.stereo import eth3d_two_view, kitti_d1, middlebury

    est, gt = _read_map(a.est), _read_map(a.gt)
    noc = _read_map(a.gt_noc) if a.gt_noc else None
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
    return {"est": a.est, "gt": a.gt, "gt_noc": a.gt_noc, "obj_map": a.obj_map, "benchmark": a.benchmark}, res


def _cmd_depth(a):
    from recon_eval.depth import eigen_depth_metrics

    res = {"eigen": eigen_depth_metrics([_read_map(a.est)], [_read_map(a.gt)], alignment=a.alignment,
                                        min_depth_m=a.min_depth, max_depth_m=a.max_depth)}
    return {"est": a.est, "gt": a.gt, "alignment": a.alignment}, res


def _cmd_fmatrix(a):
    from recon_eval.epipolar import fundamental_metrics, zhang_f_distance
    from recon_eval.errors import InputError
    from recon_eval.readers.matrix import read_matrix3
    from recon_eval.readers.npy import read_npy

    F = read_matrix3(a.f_est, key="F")
    m = read_npy(a.matches, (None, 4))
    res = {"fundamental": fundamental_metrics(F, m[:, :2], m[:, 2:])}
    if a.f_gt:
        if not a.size:
            raise InputError("--f-gt needs --size W H for Zhang's F-distance")
        res["zhang_f_distance"] = zhang_f_distance(F, read_matrix3(a.f_gt, key="F"), tuple(a.size))
    return {"f_est": a.f_est, "matches": a.matches, "f_gt": a.f_gt, "size": a.size}, res


def _cmd_homography(a):
    from recon_eval.epipolar import homography_mace, homography_summary
    from recon_eval.readers.matrix import read_matrix3

    r = homography_mace(read_matrix3(a.h_est, key="H"), read_matrix3(a.h_gt, key="H"), *a.size)
    return {"h_est": a.h_est, "h_gt": a.h_gt, "size": a.size}, {"homography": r, "summary": homography_summary([r.mace_px])}


_COMMANDS = {"cloud": _cmd_cloud, "poses": _cmd_poses, "disparity": _cmd_disparity, "depth": _cmd_depth,
             "fmatrix": _cmd_fmatrix, "homography": _cmd_homography}


def main(argv=None) -> int:
    args = _parser().parse_args(argv)  # argparse itself exits with code 2 on bad usage
    from recon_eval.errors import InputError
    from recon_eval.report import document, print_table, write_json_atomic

    try:
        inputs, results = _COMMANDS[args.command](args)
        if not args.quiet:
            print_table(f"recon-eval {args.command}", results)
        if args.json:
            write_json_atomic(args.json, document(args.command, inputs, results))
    except InputError as exc:
        print(f"recon-eval: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OSError as exc:  # unreadable input or unwritable output
        print(f"recon-eval: error: {exc.filename or ''}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0


if __name__ == "__main__":
    sys.exit(main())
