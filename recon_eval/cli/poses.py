"""``recon-eval poses``: estimated camera poses against the truth, any pair of pose sources the
readers registry sniffs (:func:`recon_eval.readers.registry.read_poses`; docs/metrics.md,
"Camera poses")."""
from __future__ import annotations

from pathlib import Path, PurePosixPath

from recon_eval.cli.scored import scored
from recon_eval.errors import InputError
from recon_eval.metrics.poses import DELTA_UNITS, POSE_ALIGNMENTS, Poses, ape, relative_pose, rpe
from recon_eval.metrics.association import associate_evo
from recon_eval.metrics.kitti_odometry import KITTI_LENGTHS_M, kitti_odometry
from recon_eval.metrics.rpg_trajectory import RPG_ALIGNMENTS
from recon_eval.metrics.sfm import reconstruction_stats
from recon_eval.readers.colmap_binary import read_colmap_binary
from recon_eval.readers.colmap_text import read_colmap_text
from recon_eval.readers.registry import read_poses
from recon_eval.readers.tum import associate
from recon_eval.report import plots
from recon_eval.report.html import Figure
from recon_eval.tasks.headlines import trajectory_headline
from recon_eval.tasks.stamped_trajectory import associated_poses, score_stamped
from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import opencv_from_colmap_pixels


def arguments(p) -> None:
    p.add_argument("est", help="COLMAP model dir, NeRF transforms.json, TUM (or ov_eval's with covariances) or KITTI "
                                 "odometry trajectory, or a dataset")
    p.add_argument("gt", help="dataset folder (cameras.json), COLMAP model dir, transforms.json, TUM or KITTI file, "
                                "EuRoC ground-truth data.csv")
    p.add_argument("--alignment", choices=list(POSE_ALIGNMENTS), default="sim3",
                   help="evo's alignments: se3 = --align, sim3 = --align --correct_scale, scale = --correct_scale "
                        "alone, origin = --align_origin (default sim3)")
    p.add_argument("--align-origin", "--align_origin", dest="alignment", action="store_const", const="origin",
                   help="evo --align_origin: same as --alignment origin")
    p.add_argument("--n-to-align", "--n_to_align", type=int, default=-1,
                   help="evo --n_to_align: fit the alignment on the first N registered cameras (default all)")
    p.add_argument("--delta", type=float, default=1, help="RPE delta (evo --delta), in --delta-unit")
    p.add_argument("--delta-unit", "--delta_unit", choices=list(DELTA_UNITS), default="f",
                   help="evo --delta_unit: f frames, m metres of path, d degrees, r radians (default f)")
    p.add_argument("--all-pairs", "--all_pairs", action="store_true",
                   help="evo --all_pairs: RPE over (i, i + delta) for every i; default: consecutive pairs "
                        "(0, d), (d, 2d), ... as plain evo_rpe")
    p.add_argument("--rpe-gaps", choices=["bridge", "fail"], default="bridge",
                   help="RPE across an unregistered camera: bridge = pair the registered poses as evo does "
                        "(default; broken truth-frame pairs still counted as failures), fail = no bridging")
    p.add_argument("--max-time-diff", "--t_max_diff", type=float, default=0.01,
                   help="TUM timestamp association: largest difference, seconds (evo --t_max_diff)")
    p.add_argument("--t-offset", "--t_offset", type=float, default=0.0,
                   help="TUM: seconds added to the estimate's stamps before association (evo --t_offset)")
    p.add_argument("--association", choices=["evo", "tum"], default="evo",
                   help="TUM stamps: evo = nearest stamp from the shorter trajectory (evo's associate_trajectories; "
                        "default), tum = unique pairs greedy by difference (TUM associate.py)")
    p.add_argument("--rpg-alignment", choices=list(RPG_ALIGNMENTS), default="sim3",
                   help="TUM stamps: rpg_trajectory_evaluation's alignment for its absolute and relative errors")
    p.add_argument("--rpg-n-aligned", type=int, default=-1,
                   help="rpg align_num_frames: align on the first N associated poses (-1 all; 1: the first pose)")
    p.add_argument("--rpg-lengths", type=float, nargs="+", metavar="M",
                   help="rpg sub-trajectory lengths, metres (default 10, 20, 30, 40, 50 %% of the truth's path)")
    p.add_argument("--drift-durations", type=float, nargs="+", metavar="S",
                   help="drift per time: sub-trajectory durations, seconds (default 10 .. 50 %% of the truth's span)")
    p.add_argument("--nees-alignment", choices=list(RPG_ALIGNMENTS), default="posyaw",
                   help="ov_eval NEES (an estimate with covariances): the truth aligned into the estimate's frame")
    p.add_argument("--kitti-lengths", type=float, nargs="+", metavar="M",
                   help="KITTI odometry segment lengths, metres (default the devkit's 100 200 ... 800)")
    p.add_argument("--camera", help="dataset truth: only the views of this spec camera (e.g. the left camera of a "
                                    "KITTI-style trajectory)")
    p.add_argument("--kitti-convention", choices=["world_from_cam", "cam_from_world"], default="world_from_cam",
                   help="what a KITTI line holds (KITTI odometry: world_from_cam of the left camera)")


def match_names_by_stem(est: Poses, gt: Poses) -> tuple[Poses, bool]:
    """Rename estimated poses whose name is not a truth name but whose file name, or file name
    without its extension, is (COLMAP ``images/cam0_000.png`` -> view ``cam0_000``)."""
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


def colmap_model_stats(model_dir):
    """COLMAP's mean reprojection error and track length of the model in ``model_dir``
    (:func:`recon_eval.metrics.sfm.reconstruction_stats`), or None for a model without tracks."""
    d = Path(model_dir)
    model = read_colmap_binary(d) if (d / "images.bin").is_file() else read_colmap_text(d)
    if len(model.track_point) == 0:
        return None
    try:
        cams = {cid: Camera.from_colmap(c.model, c.width, c.height, c.params_colmap) for cid, c in model.cameras.items()}
        per_image = [cams[cid] for cid in model.image_camera_ids]
    except (KeyError, ValueError) as exc:
        raise InputError(f"{d}: cameras: {exc}") from None
    return reconstruction_stats(per_image, model.poses.R_cam_from_world, model.poses.t_cam_from_world,
                                model.points_world, model.track_point, model.track_image,
                                opencv_from_colmap_pixels(model.track_xy_colmap))


def score(a):
    ek, est = read_poses(a.est, camera=a.camera, kitti_convention=a.kitti_convention)
    gk, gt = read_poses(a.gt, camera=a.camera, kitti_convention=a.kitti_convention)
    matching = "by name"
    if (ek == "tum") != (gk == "tum"):
        raise InputError(f"{a.est if ek == 'tum' else a.gt}: a TUM trajectory is matched by timestamps and needs a "
                         "TUM trajectory on the other side")
    stamped = None
    if ek == "tum" and a.association == "evo":
        try:
            stamped = score_stamped(est, gt, max_diff_s=a.max_time_diff, offset_s=a.t_offset,
                                    alignment=a.rpg_alignment, n_aligned=a.rpg_n_aligned, lengths_m=a.rpg_lengths,
                                    durations_s=a.drift_durations, nees_alignment=a.nees_alignment)
        except InputError as exc:  # e.g. a straight truth path: rpg's alignment undetermined; APE/RPE still scored
            stamped = f"not scored: {exc}"
        est, gt = associated_poses(est, gt, associate_evo(gt.timestamps_s, est.timestamps_s, a.max_time_diff,
                                                          a.t_offset))
        matching = f"TUM timestamps within {a.max_time_diff} s, estimate shifted by {a.t_offset} s (evo)"
    elif ek == "tum":
        if a.t_offset:
            raise InputError("--t-offset applies to --association evo")
        est, gt = associate(est, gt, a.max_time_diff), gt.poses
        matching = f"TUM timestamps within {a.max_time_diff} s"
    elif ek == "kitti" and gk != "kitti":
        # KITTI lines carry no names: line i is the i-th truth pose in truth order
        n = min(len(est.names), len(gt.names))  # lines beyond the truth keep their own names: n_extra
        est = Poses(gt.names[:n] + est.names[n:], est.R_cam_from_world, est.t_cam_from_world)
        matching = "KITTI line i = i-th truth view"
    else:
        est, renamed = match_names_by_stem(est, gt)
        if renamed:
            matching = "by name (folders and image extensions ignored where needed)"
    if len(gt.names) == 0:
        raise InputError(f"{a.gt}: the truth has no poses")
    al = a.alignment
    delta = int(a.delta) if a.delta_unit == "f" and float(a.delta).is_integer() else a.delta
    res = {"ape": ape(est, gt, alignment=al, n_to_align=a.n_to_align),
           "rpe": rpe(est, gt, delta=delta, delta_unit=a.delta_unit, all_pairs=a.all_pairs, alignment=al,
                      n_to_align=a.n_to_align, gaps=a.rpe_gaps),
           "relative_pose": relative_pose(est, gt),
           "kitti_odometry": kitti_odometry(est, gt, lengths_m=a.kitti_lengths or KITTI_LENGTHS_M)}
    if ek == "colmap":
        res["colmap_reconstruction"] = colmap_model_stats(a.est)
    if stamped is not None:
        res["vio"] = stamped
    inputs = {"est": a.est, "gt": a.gt, "format": ek, "gt_format": gk, "matching": matching,
              "alignment": a.alignment, "delta_frames": delta if a.delta_unit == "f" else None, "camera": a.camera,
              "delta": delta, "delta_unit": a.delta_unit, "all_pairs": a.all_pairs, "n_to_align": a.n_to_align,
              "rpe_gaps": a.rpe_gaps, "association": a.association if ek == "tum" else None,
              "t_offset": a.t_offset if ek == "tum" else None,
              "kitti_convention": a.kitti_convention if "kitti" in (ek, gk) else None}

    def figures():
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


COMMANDS = {"poses": scored(arguments, score, lambda a, res: trajectory_headline(res["ape"], res["rpe"], a.alignment))}
