"""Runs of third-party estimators on scenegen datasets, scored with recon_eval's metrics.

One module per method family: :mod:`.calibration` (OpenCV calibrateCamera / fisheye),
:mod:`.stereo` (StereoBM / StereoSGBM), :mod:`.twoview` (findFundamentalMat, findEssentialMat,
findHomography), :mod:`.fsurvey` (the nineteen F estimators of Armangue and Salvi's survey,
:mod:`recon_eval.estimators.fundamental`), :mod:`.pnp` (solvePnP / solvePnPRansac),
:mod:`.colmap` (pycolmap incremental SfM), :mod:`.dlt` (linear DLT camera matrices), :mod:`.triangulate` (cv2.triangulatePoints),
:mod:`.stereo_vo` (the course's stereo odometry), :mod:`.inertial` (IMU dead reckoning),
:mod:`.features` (OpenCV keypoints and descriptors, mutual nearest-neighbour matching),
:mod:`.flow` (DIS and Farneback dense flow, pyramidal Lucas-Kanade tracks), :mod:`.photometric`
(Woodham's photometric stereo, Frankot-Chellappa integration), :mod:`.near_light` (under point lights), :mod:`.focus` (depth from focus), :mod:`.shading` (shape from shading), :mod:`.texture` (shape from texture), :mod:`.zoom` (depth from zooming), :mod:`.tsdf_fusion` (KinectFusion-style TSDF fusion of depth frames),
:mod:`.external`
(a user's own command line, declared in a methods file or with ``run --command``:
:mod:`.declared`); shared:
:mod:`.common` (the run record), :mod:`.detect` (marker-board detection). :data:`METHODS` lists
the production methods; :data:`FAULTS` the deliberately broken ones of :mod:`.faults`, which gates
must catch, run by name the same way.

:func:`run_method` runs one registered method and writes ``OUT/result.json`` (the run-result
JSON, ``command: "run"``, docs/ci.md) and ``OUT/report.html`` (its summary and every scalar)
next to the raw outputs.
"""
from __future__ import annotations

import importlib
import sys
from dataclasses import dataclass
from difflib import get_close_matches
from pathlib import Path

import cv2

from recon_eval.errors import InputError, NotApplicable
from recon_eval.estimators.fundamental import ESTIMATORS as F_SURVEY
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.report.document import document, to_jsonable, write_json_atomic
from recon_eval.report.html import render_html, write_html_atomic
from recon_eval.runners.common import RUN_SCHEMA_VERSION, RunOutput, Timer


@dataclass(frozen=True)
class Method:
    name: str
    module: str  # recon_eval.runners.<module>, imported when the method runs
    function: str
    description: str
    options: tuple = ()  # (key, value) pairs passed to the function
    fault: bool = False  # a deliberately broken estimator (FAULTS)

    @property
    def task(self) -> str:
        """What the method estimates (the leaderboard page's table): :data:`TASKS`, else its module."""
        return TASKS.get((self.module, self.function), TASKS.get((self.module, None), self.module))


#: The task of each runner function ((module, function); (module, None): every function of the
#: module): methods of one task share a leaderboard table, one column per metric.
TASKS = {("calibration", None): "calibration", ("stereo", None): "stereo disparity",
         ("active_stereo", None): "active IR stereo",
         ("twoview", "fundamental"): "fundamental matrix", ("twoview", "essential"): "essential matrix",
         ("twoview", "homography"): "homography", ("pnp", None): "absolute pose (PnP)",
         ("colmap", None): "structure from motion", ("features", None): "keypoints and matches",
         ("dlt", None): "DLT camera matrices", ("triangulate", None): "triangulation",
         ("photometric", None): "photometric stereo", ("near_light", None): "photometric stereo", ("focus", "sml"): "depth from focus", ("focus", "stm"): "depth from defocus",
         ("structured_light", None): "structured light", ("procam", None): "projector-camera calibration",
         ("turntable", None): "turntable scan",
         ("shading", None): "shape from shading", ("zoom", None): "depth from zooming", ("texture", None): "shape from texture", ("flow", "dense"): "optical flow", ("flow", "lk"): "feature tracks", ("tracking", None): "point tracks (TAP-Vid)",
         ("faults", "calib_cx"): "calibration", ("faults", "f_transposed"): "fundamental matrix",
         ("external", "fmatrix"): "fundamental matrix", ("fsurvey", None): "fundamental matrix",
         ("external", "disparity"): "stereo disparity",
         ("external", "sfm"): "structure from motion", ("external", "calibration"): "calibration",
         ("external_more", "flow"): "optical flow", ("external_more", "depth"): "depth maps",
         ("external_more", "essential"): "essential matrix",
         ("external_more", "homography"): "homography", ("external_views", "features"): "keypoints and matches",
         ("external_views", "pnp"): "absolute pose (PnP)", ("external_views", "normals"): "photometric stereo",
         ("external_views", "cloud"): "point clouds and meshes", ("external_views", "triangulation"): "triangulation",
         ("external_views", "dlt"): "DLT camera matrices", ("external_sequence", "tracks"): "point tracks (TAP-Vid)",
         ("external_sequence", "trajectory"): "camera trajectory",
         ("objects_align", None): "6D object pose (BOP)", ("objects_features", None): "6D object pose (BOP)",
         ("objects_parts", None): "articulated object pose", ("tsdf_fusion", None): "TSDF fusion (depth sweep)",
         ("stereo_vo", None): "stereo odometry", ("inertial", None): "stereo odometry"}


def _m(name, module, function, description, **options):
    return Method(name, module, function, description, tuple(sorted(options.items())))


_F = ("7point", "8point", "ransac", "lmeds", "usac_default", "usac_parallel", "usac_fm_8pts", "usac_fast",
      "usac_accurate", "usac_prosac", "usac_magsac")

#: The HTML report of a run, beside its result.json.
REPORT = "report.html"

METHODS: dict[str, Method] = {m.name: m for m in [
    _m("opencv-calib-checkerboard", "calibration", "checkerboard",
       "cv2.calibrateCamera on findChessboardCorners + cornerSubPix (k1 k2 p1 p2 k3)"),
    _m("opencv-calib-charuco", "calibration", "charuco", "cv2.calibrateCamera on CharucoDetector corners"),
    _m("opencv-calib-fisheye", "calibration", "fisheye", "cv2.fisheye.calibrate on checkerboard corners"),
    _m("opencv-stereo-bm", "stereo", "run", "cv2.StereoBM on the rectified pairs", matcher="bm"),
    _m("opencv-stereo-sgbm", "stereo", "run", "cv2.StereoSGBM (3-way) on the rectified pairs", matcher="sgbm"),
    _m("opencv-sgbm-ir", "active_stereo", "run", "cv2.StereoSGBM (3-way) on the active IR pair, dot projector on",
       projector="on", matcher="sgbm"),
    _m("opencv-sgbm-ir-off", "active_stereo", "run",
       "cv2.StereoSGBM (3-way) on the active IR pair with the projector off (ambient only)", projector="off",
       matcher="sgbm"),
    *[_m(f"opencv-f-{f.replace('_', '-')}", "twoview", "fundamental", f"cv2.findFundamentalMat {f}", flag=f)
      for f in _F],
    *[_m(f"survey-f-{e.name}", "fsurvey", "fundamental", f"{e.label} ({e.cites}); numpy/scipy, Armangue and Salvi's "
         f"survey (docs/fmatrix_survey.md)", estimator=e.name) for e in F_SURVEY.values()],
    _m("opencv-e-ransac", "twoview", "essential", "cv2.findEssentialMat RANSAC", flag="ransac"),
    _m("opencv-e-lmeds", "twoview", "essential", "cv2.findEssentialMat LMEDS", flag="lmeds"),
    _m("opencv-e-usac-magsac", "twoview", "essential", "cv2.findEssentialMat USAC_MAGSAC", flag="usac_magsac"),
    _m("opencv-h-ransac", "twoview", "homography", "cv2.findHomography RANSAC on one plane's matches", flag="ransac"),
    _m("opencv-h-usac-magsac", "twoview", "homography", "cv2.findHomography USAC_MAGSAC", flag="usac_magsac"),
    *[_m(f"opencv-pnp-{s}", "pnp", "run", f"cv2.solvePnP SOLVEPNP_{s.upper()}", solver=s, ransac=False)
      for s in ("iterative", "epnp", "sqpnp", "ippe", "ap3p")],
    *[_m(f"opencv-pnp-ransac-{s}", "pnp", "run", f"cv2.solvePnPRansac SOLVEPNP_{s.upper()}", solver=s, ransac=True)
      for s in ("iterative", "epnp", "sqpnp", "ap3p")],
    _m("pycolmap-incremental", "colmap", "incremental",
       "pycolmap extract_features + match_exhaustive + incremental_mapping"),
    *[_m(f"opencv-features-{d}", "features", "run",
         f"cv2.{d.upper()}_create() (default parameters), BFMatcher mutual nearest neighbours", detector=d)
      for d in ("sift", "orb", "akaze", "brisk")],
    _m("dlt-linear", "dlt", "linear",
       "normalised linear DLT (H&Z Alg. 7.1, linear steps) on detected board corners and on noisy truth points"),
    _m("opencv-triangulate", "triangulate", "opencv",
       "cv2.triangulatePoints on noisy exact truth correspondences of the cross-view pairs (sigma 0 and 1 px)"),
    _m("opencv-flow-dis", "flow", "dense", "cv2.DISOpticalFlow (preset medium) on the flow pairs", algorithm="dis"),
    _m("opencv-flow-farneback", "flow", "dense", "cv2.calcOpticalFlowFarneback (tutorial parameters) on the flow pairs",
       algorithm="farneback"),
    _m("opencv-lk-tracks", "flow", "lk", "cv2.goodFeaturesToTrack + calcOpticalFlowPyrLK (21 px, 3 levels) tracks"),
    _m("opencv-lk-tapvid", "tracking", "lk_tapvid",
       "chained cv2.calcOpticalFlowPyrLK (21 px, 3 levels, forward-backward check) from the truth query points"),
    _m("woodham-ps", "photometric", "run",
       "Woodham's least-squares photometric stereo (calibrated lights, shadows below 0.02 left out), "
       "Frankot-Chellappa integration to depth (numpy)", shadow_threshold=0.02),
    _m("woodham-near-ps", "near_light", "woodham_near",
       "near-light photometric stereo: Woodham per pixel with the point lights' own directions and 1/r^2, "
       "alternated with Frankot-Chellappa depth (4 rounds)", shadow_threshold=0.02, iterations=4),
    _m("sml-dff", "focus", "sml",
       "depth from focus: sum-modified-Laplacian (9 x 9 window), Gaussian peak interpolation in inverse depth",
       window=4),
    _m("stm-dfd", "focus", "stm",
       "depth from defocus, two images: Subbarao and Surya's spatial-domain transform (Gaussian window 4 px), "
       "thin-lens blur to depth in closed form", window_px=4.0),
    _m("sl-gray-code", "structured_light", "gray",
       "Gray-code decoder: each bit from the pattern against its inverse (unreliable below 0.1 of the pixel's "
       "white - black contrast), Gray to binary, camera ray against the decoded projector column", threshold=0.1,
       min_contrast=0.005, triangulation="plane", tau_m=0.001),
    _m("sl-gray-code-rays", "structured_light", "gray",
       "Gray-code decoder as sl-gray-code, midpoint of the camera ray and the projector ray of (column, row)",
       threshold=0.1, min_contrast=0.005, triangulation="rays", tau_m=0.001),
    _m("sl-phase-shift", "structured_light", "phase",
       "N-step phase shifting with hierarchical temporal unwrapping, camera ray against the continuous column",
       min_modulation=0.005, tau_m=0.001),
    _m("sl-procam-calib", "procam", "run",
       "projector-camera calibration (Moreno and Taubin 2012): Gray codes decoded, local homographies (29 x 29 px) "
       "carry the board corners into the projector, cv2.calibrateCamera for each, cv2.stereoCalibrate",
       half_window_px=14, threshold=0.1, min_contrast=0.005),
    _m("sl-turntable-gray", "turntable", "run",
       "turntable scan: sl-gray-code per step, the clouds registered with the known turntable motion, merged, "
       "cropped to the object's box + 2 mm", threshold=0.1, min_contrast=0.005, tau_m=0.001, crop_margin_m=0.002),
    _m("ikeuchi-horn-sfs", "shading", "run",
       "shape from shading: Ikeuchi-Horn iterations from the occluding boundary, Frankot-Chellappa "
       "integrability each iteration (200 iterations, step 8), light and albedo known", iterations=200, step=8.0),
    _m("sift-zoom-depth", "zoom", "radial",
       "depth from zooming: SIFT matches from the widest view, depth from the radial magnification with the "
       "calibrated focal lengths and pupil travel", min_radius_px=15.0),
    _m("texture-structure-tensor", "texture", "structure_tensor",
       "shape from texture: slant and tilt of a textured plane from its mean normalised structure tensor "
       "(isotropic texture, orthographic foreshortening), tilt sign from the texture's density gradient",
       window_px=4.0),
    _m("o3d-fpfh-ransac-icp", "objects_align", "run",
       "alignment: Open3D FPFH + RANSAC global registration of each model to each depth cluster (table plane "
       "removed, DBSCAN), point-to-plane ICP, 4 trials verified by rendered depth; BOP19 CSV"),
    _m("sift-pnp-ransac", "objects_features", "run",
       "invariant features: SIFT matches from the reference renders (train split) of each model to the image, "
       "cv2.solvePnPRansac (EPnP + refinement); BOP19 CSV"),
    _m("parts-align-joints", "objects_parts", "run",
       "parts: each part of an articulated object posed alone by the alignment method, joints recovered as the "
       "parts' relative rotations; BOP19 CSV, per-part and joint errors"),
    _m("o3d-tsdf-fusion", "tsdf_fusion", "run",
       "KinectFusion-style: Open3D VoxelBlockGrid TSDF fusion (4 mm voxels) of the depth frames with the truth "
       "poses and with poses tracked frame to frame (point-to-plane ICP), marching cubes; scored against the "
       "truth mesh (Tanks and Temples F at 5 / 10 mm, DTU) and the tracked trajectory's APE"),
    _m("stereo-vo-pnp", "stereo_vo", "run",
       "stereo odometry: goodFeaturesToTrack corners, LK left-right matching along rows, stereo triangulation, "
       "LK temporal tracks, solvePnPRansac (EPnP) + LM against the previous frame, chained; steps rejected "
       "against the gyroscope (1 deg) replaced by it (constant velocity); TUM trajectory"),
    _m("imu-dead-reckoning", "inertial", "run",
       "IMU-only baseline: RK4 integration of the measured IMU stream from the true initial state; TUM trajectory"),
]}

#: Deliberately broken estimators (:mod:`.faults`): for showing that gates fail, never for results.
FAULTS: dict[str, Method] = {m.name: m for m in [
    Method("broken-calib-cx", "faults", "calib_cx", "DELIBERATELY BROKEN: checkerboard calibration, cx + 2 px",
           fault=True),
    Method("broken-f-transposed", "faults", "f_transposed", "DELIBERATELY BROKEN: RANSAC F, transposed",
           tuple(sorted({"flag": "ransac", "transpose": True}.items())), fault=True),
]}


def method(name: str, declared: dict | None = None) -> Method:
    """The registered method ``name``: a production method, else a fault, else one of the user's
    ``declared`` methods (:mod:`.declared`: external commands); InputError otherwise."""
    declared = declared or {}
    for table in (METHODS, FAULTS, declared):
        if name in table:
            return table[name]
    close = get_close_matches(name, list(METHODS) + list(FAULTS) + list(declared), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    mine = f"; declared: {', '.join(declared)}" if declared else ""
    raise InputError(f"unknown method {name!r}{hint}; known: {', '.join(METHODS)}; faults: {', '.join(FAULTS)}"
                     f"{mine}")


def run_method(name: str, dataset, out_dir, *, write: bool = True, declared: dict | None = None) -> dict:
    """Run method ``name`` (built-in, fault or one of ``declared``) on the dataset folder
    ``dataset``; raw outputs and ``result.json`` go to ``out_dir``. Returns the result document.
    Raises InputError (NotApplicable when the dataset lacks what the method needs)."""
    m = method(name, declared)
    ds = read_dataset(dataset)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fn = getattr(importlib.import_module(f"recon_eval.runners.{m.module}"), m.function)
    with Timer() as t:
        res: RunOutput = fn(ds, out, dict(m.options))
    for w in res.warnings:
        print(f"recon-eval: warning: {m.name}: {w}", file=sys.stderr)
    inputs = {"method": m.name, "task": m.task, "description": m.description, "options": dict(m.options),
              "dataset": str(dataset), "scene": ds.scene_name, "raw_files": res.raw_files,
              "notes": res.notes, "seconds": t.s, "opencv_version": cv2.__version__,
              "run_schema_version": RUN_SCHEMA_VERSION}
    if res.warnings:
        inputs["warnings"] = list(res.warnings)
    doc = document("run", inputs, res.results)
    doc["metrics"] = to_jsonable(res.metrics)
    if write:
        write_json_atomic(out / "result.json", doc)
        write_html_atomic(out / REPORT, render_html("run", inputs, res.results, [], metrics=res.metrics))
    return doc


__all__ = ["METHODS", "FAULTS", "Method", "NotApplicable", "RunOutput", "method", "run_method"]
