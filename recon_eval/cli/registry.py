"""The one table of ``recon-eval`` subcommands: name, help, and the family module that implements
it. This module imports nothing heavy, so ``recon-eval --help`` lists every command without
loading numpy, OpenCV or the dataset reader; a family module is imported only for its own commands.

Every family module (``recon_eval.cli.<family>``) registers its commands the same way: a dict
``COMMANDS`` of command name -> :class:`Impl` (a function adding the command's arguments to its
parser, and ``run(args) -> exit code``). Scored commands, which write recon_eval's versioned
report, are built by :func:`recon_eval.cli.scored.scored` around a function returning
``(inputs, results, figures)``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Command:
    name: str
    help: str
    family: str  # the module recon_eval.cli.<family> that implements it
    description: str = ""  # the command's --help text, when it says more than ``help``


@dataclass(frozen=True)
class Impl:
    """A family module's implementation of one command."""

    arguments: Callable  # (argparse.ArgumentParser) -> None
    run: Callable  # (argparse.Namespace) -> exit code (0 ok, 1 a gate failed; bad input raises InputError)


COMMANDS: tuple[Command, ...] = (
    Command("cloud", "point cloud / mesh: Tanks and Temples, ETH3D, DTU, Chamfer", "cloud"),
    Command("poses", "camera poses: APE, RPE, registration ratio, relative-pose AUC and mAA", "poses"),
    Command("disparity", "stereo disparity: KITTI D1, Middlebury, ETH3D two-view", "maps"),
    Command("depth", "depth maps: Eigen abs_rel, sq_rel, rmse, rmse_log, a1..a3", "maps"),
    Command("depth-sensor", "a ToF stream's range against its truth: error by range and incidence, completeness "
                            "map, flying-pixel edges; Eigen depth metrics", "depth_sensor"),
    Command("flow", "optical flow: EPE all/noc/occ, KITTI Fl bg/fg/all, Sintel s0-10/s10-40/s40+", "flow"),
    Command("tracks", "point tracks over a sequence: TAP-Vid AJ, < delta_avg, OA against the truth tracks", "tracks"),
    Command("normals", "normal maps (photometric stereo): DiLiGenT mean/median angular error, < 10/20/30 deg; "
                       "albedo up to scale; light directions", "photometric"),
    Command("objects", "6D object poses (BOP19 CSV) and keypoints (COCO results): BOP19 AR (VSD, MSSD, MSPD), "
                       "ADD/ADD-S recall, COCO keypoint AP, PCK", "objects"),
    Command("codes", "structured light code maps: agreement with the truth codes over lit pixels, completeness, "
                     "code error in projector pixels; the decoder's cloud", "structured_light"),
    Command("fmatrix", "fundamental matrix: Sampson, symmetric epipolar, Zhang distance, pose via K", "twoview"),
    Command("sweep", "F, H, E, PnP or triangulation estimators over noise and outliers on exact truth: per-cell "
                     "error statistics, breakdown points", "sweep",
            description="Sweep estimators of one kind (--kind f, h, e, pnp, triangulation) over Gaussian noise and "
                        "outlier fractions drawn from DATASET's exact truth (docs/fmatrix_survey.md, docs/sweeps.md)."),
    Command("homography", "homography: mean corner error, accuracy and AUC", "twoview"),
    Command("calibration", "intrinsics: fx/fy/cx/cy errors, projection difference field, reprojection RMS", "camera"),
    Command("cam-imu", "camera-IMU calibration (Kalibr camchain-imucam.yaml): extrinsic rotation and translation, "
                       "time offset against the truth", "cam_imu"),
    Command("pnp", "absolute pose: rotation angle, translation error, reprojection RMS", "camera"),
    Command("features", "keypoints and matches: repeatability, MMA@1..10, matching score, precision and recall "
                        "per image pair and series", "features"),
    Command("dlt", "DLT camera matrix: RQ into K, R, t; intrinsics, pose and reprojection errors", "geometry"),
    Command("triangulation-task", "write a triangulation task: camera pairs with noisy truth correspondences",
            "geometry"),
    Command("triangulation", "triangulated points against the truth, binned by triangulation angle", "geometry"),
    Command("lidar-deskew", "a de-skewed LiDAR sweep against the per-beam truth at the sweep's start or end",
            "lidar"),
    Command("lidar-range", "LiDAR range error against the truth, binned by range and incidence angle", "lidar"),
    Command("run", "run an estimator on a dataset, keep its raw output, score it", "ci",
            description="Run METHOD on DATASET; raw output and result.json go to -o RESULTS."),
    Command("leaderboard", "run methods on datasets; write leaderboard.md/.json/.html", "ci",
            description="Run every METHOD on every DATASET (inapplicable pairs are skipped)."),
    Command("gate", "check run results against a gate file (exit 1 when any gate fails)", "ci",
            description="Check results against GATES; exit 0 all hold, 1 any fails, 2 bad input."),
)
BY_NAME: dict[str, Command] = {c.name: c for c in COMMANDS}
