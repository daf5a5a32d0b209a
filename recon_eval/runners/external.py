"""External methods: a user's own estimator, declared as a command line and an output kind, run
and scored exactly like a built-in method (docs/ci.md, "Your own estimator").

A method is declared in a methods file (YAML, read by :mod:`scenegen.located_yaml`; errors name
file:line: field)::

    version: 1
    methods:
      - name: my-fmatrix                       # [A-Za-z0-9_.-], not a built-in name
        kind: fmatrix                          # one of KINDS
        command: "{python} examples/my_fmatrix.py {images} {out}"
        timeout_s: 120                         # per invocation (default 600)
        pixels: distorted                      # fmatrix on images: the pixels F is for (default distorted)
        description: 8-point F on SIFT matches # optional

or on the command line (``recon-eval run --command CMD --kind KIND [--name NAME]``). Either way it
becomes a :class:`recon_eval.runners.Method` of this module and runs through
:func:`recon_eval.runners.run_method`: the same result.json, leaderboard row and gates.

The command is split with :func:`shlex.split` and run without a shell (an argument list), in the
current directory, once per item of the kind (a pair, a stereo frame). Placeholders ``{name}``
are replaced by paths recon-eval made (absolute; dataset files, or files in the run folder) or by
view names checked as dataset names; a placeholder standing alone that holds several paths
(``{images}``) becomes several arguments. The invocation's stdout and stderr are kept in the run
folder (``<item>/stdout.txt``, ``stderr.txt``); a non-zero exit, a timeout or a missing or
unreadable output is scored as a failed estimate of that item (never dropped), with the exit
status and the last lines of stderr in the result's notes.
"""
from __future__ import annotations

import re
import shlex
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.readers.matrix import read_matrix3
from recon_eval.readers.npy import read_mask
from recon_eval.readers.pfm import read_pfm
from recon_eval.runners import calibration as calib, colmap, stereo, twoview
from recon_eval.runners.common import RunOutput, crossview_pairs, out_path
from recon_eval.runners.process_group import run_group
from recon_eval.tasks.fmatrix_pair import PIXELS, headline, pair_truth, score_pair, unusable_f_warning
from scenegen.dataset.layout import check_view_name

#: Default per-invocation timeout, seconds.
TIMEOUT_S = 600.0
#: Lines of stderr kept in the notes of a failed invocation.
STDERR_LINES = 12
PLACEHOLDER = re.compile(r"\{([A-Za-z0-9_]*)\}")


@dataclass(frozen=True)
class Kind:
    """An output kind: what the command is given and must write, and how it is scored."""

    name: str
    function: str  # the runner function of ``module``
    placeholders: tuple  # the names the command may use ({python} and {dataset} always)
    contract: str  # one line for --help and the docs
    module: str = "external"  # recon_eval.runners.<module>: this one, or external_more


KINDS: dict[str, Kind] = {k.name: k for k in [
    Kind("fmatrix", "fmatrix", ("images", "image1", "image2", "view1", "view2", "matches", "inliers", "out"),
         "per cross-view pair: write F (3x3 text, x2^T F x1 = 0) to {out}. With {images} / {image1} {image2} the "
         "images are given and F is scored on the truth correspondences; with {matches} (an (N, 4) .npy of a "
         "labelled match set, undistorted pixels x1 y1 x2 y2) it runs per match set, may write an inlier mask "
         "(.npy, N) to {inliers}, and is scored as the built-in F methods"),
    Kind("disparity", "disparity", ("left", "right", "view1", "out"),
         "per rectified stereo frame: read {left} {right} (PNG), write the left disparity (PFM, px; inf/nan = none) "
         "to {out}; scored as the built-in stereo methods"),
    Kind("calibration", "calibration", ("images", "camera", "out"),
         "per spec camera: {images} is a folder of its views' images (<view>.png), {camera} its name; write its "
         "calibration (OpenCV YAML/JSON: camera_matrix, distortion_coefficients, image size) to {out}; scored as "
         "the built-in calibration methods"),
    Kind("sfm", "sfm", ("images", "out"),
         "once: {images} is a folder of <view>.png, write a COLMAP model (cameras, images, points3D; .bin or .txt; "
         "image names <view>.png) into the folder {out}; scored as pycolmap-incremental"),
    Kind("flow", "flow", ("image1", "image2", "view1", "view2", "out"),
         "per flow pair (a sequence's frame pairs, else both directions of each cross-view pair): read {image1} "
         "{image2}, write the flow image1 -> image2 (Middlebury .flo, px) to {out}; scored as opencv-flow-dis",
         "external_more"),
    Kind("depth", "depth", ("image", "view", "out"),
         "per view: read {image}, write its z-depth (an (H, W) .npy, metres; NaN/inf/<=0 = none) to {out}; Eigen's "
         "metrics without alignment and with median scaling, as recon-eval depth", "external_more"),
    Kind("essential", "essential", ("images", "image1", "image2", "view1", "view2", "k1", "k2", "out"),
         "per cross-view pair: read {images} and the intrinsics {k1} {k2} (3x3 text), write E (3x3 text, "
         "x2n^T E x1n = 0 on normalised undistorted coordinates) to {out}; the pose recovered on the truth "
         "correspondences is scored as the built-in E methods", "external_more"),
    Kind("homography", "homography", ("images", "image1", "image2", "view1", "view2", "plane", "mask", "out"),
         "per cross-view pair and plane with a truth homography: read {images}, {plane} (its name) and {mask} (PNG of "
         "image 1, 255 on the plane); write H (3x3 text, x2 ~ H x1, undistorted pixels) to {out}; the mean corner "
         "error as the built-in H methods", "external_more"),
    Kind("features", "features", ("images", "pairs", "out"),
         "once: {images} is a folder of <view>.png, {pairs} a text file of the cross-view pairs (view_i view_j per "
         "line); write keypoints/<view>.txt and matches/<view_i>__<view_j>.txt (docs/features.md) into the folder "
         "{out}; scored as opencv-features-* and recon-eval features", "external_views"),
    Kind("pnp", "pnp", ("image", "view", "points", "k", "dist", "out"),
         "per view: {points} is an (N, 5) .npy of u v X Y Z (noisy truth pixels with 30 % outliers, world metres), "
         "{k} and {dist} the camera's K (3x3) and OpenCV distortion (text); write cam_from_world [R | t] (3x4 text) "
         "to {out}; scored as the built-in PnP methods' points input", "external_views"),
    Kind("normals", "normals", ("images", "lights", "intensities", "mask", "out"),
         "per photometric stereo set under distant lights: {images} its images in order, {lights} light_directions.txt "
         "and {intensities} light_intensities.txt (DiLiGenT's axes), {mask} (PNG, 255 on the objects); write an "
         "(H, W, 3) .npy normal map in DiLiGenT's axes to {out}; DiLiGenT's errors as woodham-ps", "external_views"),
    Kind("cloud", "cloud", ("images", "out"),
         "once: {images} is a folder of <view>.png (the cameras: {dataset}/cameras.json); write a point cloud or mesh "
         "(.ply) to {out}; Tanks and Temples at 1 cm and Chamfer-L1 against the scene's meshes as recon-eval cloud",
         "external_views"),
    Kind("triangulation", "triangulation", ("task", "out"),
         "per triangulation task of opencv-triangulate (pixel noise 0 and 1 px): {task} the task folder (<pair>/P1.txt, "
         "P2.txt, observations.txt); write <pair>.txt (X Y Z per observation row) into the folder {out}; scored as "
         "opencv-triangulate", "external_views"),
    Kind("dlt", "dlt", ("points", "view", "out"),
         "per view and input of dlt-linear (detected board corners, noisy truth points): {points} an (N, 5) .npy of "
         "u v X Y Z (undistorted px, world m); write the camera matrix P (3x4 text) to {out}; scored as dlt-linear",
         "external_views"),
    Kind("tracks", "tracks", ("images", "queries", "out"),
         "per point-track stream of a sequence: {images} its frames in order, {queries} an (N, 3) .npy of query points "
         "t y x; write an .npz of tracks_xy (N, T, 2) px and occluded (N, T) to {out}; TAP-Vid's metrics as "
         "opencv-lk-tapvid", "external_sequence"),
    Kind("trajectory", "trajectory", ("images", "times", "camera", "k", "dist", "out"),
         "per camera stream of 3+ frames: {images} its frames in time order, {times} lines 'timestamp image', {k} "
         "{dist} its K and distortion (text); write a TUM trajectory (timestamp tx ty tz qx qy qz qw, world_from_cam) "
         "to {out}; APE (Sim(3)) and RPE as recon-eval poses", "external_sequence"),
]}
ALWAYS = ("python", "dataset")
#: ``declared_at`` of a method made by ``recon-eval run --command``, and the option of each field
#: there: its errors name what the user typed (a methods file's name FILE:LINE: field).
CLI = "--command"
CLI_OPTIONS = {"name": "--name", "kind": "--kind", "command": "--command", "timeout_s": "--timeout",
               "pixels": "--pixels"}


def field_at(declared_at: str, field: str) -> str:
    """Where an error about a method's ``field`` points: its option, for a method declared on the
    command line (``declared_at`` :data:`CLI`), else ``<declared_at>: <field>``."""
    return CLI_OPTIONS[field] if declared_at == CLI else f"{declared_at}: {field}"


def check_command(command: str, kind: str, where: str) -> list[str]:
    """The argument list of ``command`` (shlex), checked: known kind, placeholders of that kind,
    ``{out}`` used; InputError naming ``where`` otherwise."""
    if kind not in KINDS:
        raise InputError(f"{field_at(where, 'kind')}: expected one of {', '.join(KINDS)}, got {kind!r}")
    try:
        argv = shlex.split(command)
    except ValueError as exc:
        raise InputError(f"{field_at(where, 'command')}: cannot split {command!r} ({exc})") from None
    if not argv:
        raise InputError(f"{field_at(where, 'command')}: empty")
    allowed = set(KINDS[kind].placeholders) | set(ALWAYS)
    used = {m for tok in argv for m in PLACEHOLDER.findall(tok)}
    unknown = sorted(used - allowed)
    if unknown:
        raise InputError(f"{field_at(where, 'command')}: unknown placeholder {{{unknown[0]}}} for kind {kind!r} "
                         f"(known: "
                         f"{', '.join('{' + n + '}' for n in KINDS[kind].placeholders + ALWAYS)})")
    if "out" not in used:
        raise InputError(f"{field_at(where, 'command')}: needs {{out}}, where the method writes its output")
    if kind == "fmatrix" and "matches" in used and used & {"images", "image1", "image2"}:
        raise InputError(f"{field_at(where, 'command')}: use {{matches}} or the images, not both")
    return argv


def substitute(argv: list[str], values: dict) -> list[str]:
    """``argv`` with each ``{name}`` replaced by ``values[name]`` (a str, or a list of str that
    must stand alone in its argument and becomes several arguments)."""
    out = []
    for tok in argv:
        whole = PLACEHOLDER.fullmatch(tok)
        if whole and isinstance(values.get(whole.group(1)), list):
            out += [str(v) for v in values[whole.group(1)]]
            continue

        def one(m):
            v = values[m.group(1)]
            if isinstance(v, list):
                raise InputError(f"command: {{{m.group(1)}}} holds several paths and must be an argument of its own")
            return str(v)

        out.append(PLACEHOLDER.sub(one, tok))
    return out


def invoke(options: dict, values: dict, log_dir: Path, item: str, out) -> str | None:
    """Run the method's command for one item; None on success, else why it failed (also recorded
    in ``out.notes[item]`` with the tail of stderr). A command that cannot start is bad input."""
    argv = substitute(check_command(options["command"], options["kind"], options.get("declared_at", CLI)),
                      {"python": sys.executable, **values})
    log_dir.mkdir(parents=True, exist_ok=True)
    timeout = float(options.get("timeout_s", TIMEOUT_S))
    try:  # in its own process group, killed with the command (runners/process_group.py)
        status = run_group(argv, log_dir / "stdout.txt", log_dir / "stderr.txt", timeout)
    except OSError as exc:
        where = "" if options.get("declared_at", CLI) == CLI else f"{options['declared_at']}: "  # the methods file
        raise InputError(f"{where}method {options['name']!r}: cannot run {argv[0]!r}: {exc.strerror or exc}") from None
    why = (f"timed out after {timeout:g} s" if status is None else None if status == 0 else
           f"killed by signal {-status}" if status < 0 else f"exit status {status}")
    if why is not None:
        tail = _last_lines(log_dir / "stderr.txt")
        out.notes[item] = {"failed": why, "stderr_tail": tail, "argv": argv}
        print(f"recon-eval: {options['name']}: {item}: {why}" + (f": {tail[-1]}" if tail else ""),
              file=sys.stderr)
    return why


def _last_lines(path: Path) -> list[str]:
    """The last :data:`STDERR_LINES` lines of a log file (of its last 64 KiB)."""
    with open(path, "rb") as f:
        f.seek(max(0, f.seek(0, 2) - (64 << 10)))
        return f.read().decode("utf-8", "replace").strip().splitlines()[-STDERR_LINES:]


def failed_output(out, item: str, why: str) -> None:
    """Record (notes) and say (stderr) that the method's output for ``item`` is missing or unreadable."""
    out.notes.setdefault(item, {})["failed"] = why
    print(f"recon-eval: {item}: {why}", file=sys.stderr)


def _read_f(path: Path, out, item: str):
    if not path.is_file():
        failed_output(out, item, f"wrote no {path.name}")
        return None
    try:
        return read_matrix3(path, key="F")
    except InputError as exc:
        failed_output(out, item, str(exc))
        return None


def fmatrix(ds, out_dir, options) -> RunOutput:
    """The ``fmatrix`` kind (:data:`KINDS`)."""
    argv = check_command(options["command"], "fmatrix", options.get("declared_at", CLI))
    if any("{matches}" in t for t in argv):
        return _fmatrix_matches(ds, out_dir, options)
    pixels = options.get("pixels", "distorted")
    if pixels not in PIXELS:
        raise InputError(f"{field_at(options.get('declared_at', CLI), 'pixels')}: expected one of {', '.join(PIXELS)}")
    pairs = crossview_pairs(ds)
    out = RunOutput()
    for i, j in pairs:
        key = f"{check_view_name(i)}__{check_view_name(j)}"
        if ds.truth_fundamental(i, j)[0] is None:
            out.notes[key] = twoview.ZERO_BASELINE_NOTE
            continue
        fpath = out_path(out_dir, f"{key}/F.txt")
        fpath.unlink(missing_ok=True)
        images = [str(ds.image_path(i).resolve()), str(ds.image_path(j).resolve())]
        values = {"images": images, "image1": images[0], "image2": images[1], "view1": i, "view2": j,
                  "out": str(fpath.resolve()), "dataset": str(Path(ds.root).resolve())}
        failed = invoke(options, values, fpath.parent, key, out)
        F = None if failed else _read_f(fpath, out, key)
        if F is None:
            F = np.full((3, 3), np.nan)
        else:
            out.raw_files.append(f"{key}/F.txt")
        truth = pair_truth(ds, i, j, pixels=pixels, max_points=twoview.TRUTH_POINTS)
        res = score_pair(F, truth, zhang_if_failed=False)
        if failed is None and out.notes.get(key, {}).get("failed") is None:  # the method's own F, unusable
            if w := unusable_f_warning(res["fundamental"], key):
                out.warnings.append(w)
        for group, r in res.items():
            out.results[f"{key}.{group}"] = r
        out.metrics.update(headline(res, "" if len(pairs) == 1 else f"{key}."))
        out.notes[f"{key}.truth"] = truth.notes
    if not out.results:
        raise NotApplicable(f"{ds.root}: the cross-view pairs are all zero-baseline: no fundamental matrix to estimate")
    return out


def _fmatrix_matches(ds, out_dir, options) -> RunOutput:
    """The fmatrix kind on the labelled match sets: the built-in F runner with the command as its fit."""
    def fit(i, j, kind, x1, x2):
        item = f"{check_view_name(i)}__{check_view_name(j)}/{kind}"
        d = Path(out_dir) / item
        d.mkdir(parents=True, exist_ok=True)
        mpath, fpath, ipath = d / "matches.npy", d / "F.txt", d / "inliers.npy"
        for p in (fpath, ipath):
            p.unlink(missing_ok=True)
        np.save(mpath, np.concatenate([x1, x2], axis=1))
        values = {"matches": str(mpath.resolve()), "out": str(fpath.resolve()), "inliers": str(ipath.resolve()),
                  "view1": i, "view2": j, "dataset": str(Path(ds.root).resolve())}
        if invoke(options, values, d, item, res_holder):
            return None, None
        F = _read_f(fpath, res_holder, item)
        mask = None
        if F is not None and ipath.is_file():
            try:
                mask = read_mask(ipath, len(x1))
            except InputError as exc:
                failed_output(res_holder, item, str(exc))
                return None, None
        return F, mask

    res_holder = RunOutput()
    out = twoview.fundamental(ds, out_dir, {"flag": "external"}, fit=fit)
    out.notes.update(res_holder.notes)
    return out


def disparity(ds, out_dir, options) -> RunOutput:
    """The ``disparity`` kind (:data:`KINDS`): the built-in stereo scoring with the command as matcher."""
    def compute(ds_, left, path, out) -> None:
        path.unlink(missing_ok=True)
        values = {"left": str(ds_.stereo_image_path(left, "left").resolve()),
                  "right": str(ds_.stereo_image_path(left, "right").resolve()), "view1": check_view_name(left),
                  "out": str(Path(path).resolve()), "dataset": str(Path(ds_.root).resolve())}
        if invoke(options, values, Path(out_dir) / "logs" / left, left, out) is None:
            if not path.is_file():
                failed_output(out, left, f"wrote no {path.name}")
                return
            try:
                read_pfm(path)
            except InputError as exc:
                failed_output(out, left, str(exc))
                path.unlink()
        else:
            path.unlink(missing_ok=True)

    return stereo.run(ds, out_dir, options, compute=compute)


def sfm(ds, out_dir, options) -> RunOutput:
    """The ``sfm`` kind (:data:`KINDS`): the built-in SfM scoring of the model the command wrote."""
    if len(ds.views) < 3:
        raise NotApplicable(f"{ds.root}: SfM needs at least 3 views, the dataset has {len(ds.views)}")
    images, model = out_path(out_dir, "images/x").parent, Path(out_dir) / "model"
    shutil.rmtree(images, ignore_errors=True)
    shutil.rmtree(model, ignore_errors=True)
    images.mkdir(parents=True)
    model.mkdir()
    for v in ds.views:
        shutil.copy(ds.image_path(v), images / f"{check_view_name(v)}.png")
    out = RunOutput()
    why = invoke(options, {"images": str(images.resolve()), "out": str(model.resolve()),
                           "dataset": str(Path(ds.root).resolve())}, Path(out_dir) / "logs", "sfm", out)
    shutil.rmtree(images, ignore_errors=True)  # the copies of the images
    files = sorted(str(f.relative_to(out_dir)) for f in model.iterdir() if f.is_file())
    if why is None:
        try:
            colmap.score_model(ds, model, out)
            out.raw_files += files
            return out
        except InputError as exc:  # an unreadable model is the method's failure, not bad input
            failed_output(out, "sfm", str(exc))
    out.metrics.update({"registration_ratio": 0.0, "max_rot_err_deg": float("inf")})
    return out


def calibration(ds, out_dir, options) -> RunOutput:
    """The ``calibration`` kind (:data:`KINDS`): the built-in calibration scoring of each camera's file."""
    groups: dict = {}
    for v in ds.views:
        groups.setdefault(ds.view_info(v).get("camera_name"), []).append(v)
    out = RunOutput()
    for cam, views in groups.items():
        name = check_view_name(str(cam))
        images, yaml_path = Path(out_dir) / f"images_{name}", out_path(out_dir, f"calibration_{name}.yaml")
        shutil.rmtree(images, ignore_errors=True)
        yaml_path.unlink(missing_ok=True)
        images.mkdir(parents=True)
        for v in views:
            shutil.copy(ds.image_path(v), images / f"{check_view_name(v)}.png")
        why = invoke(options, {"images": str(images.resolve()), "camera": name, "out": str(yaml_path.resolve()),
                               "dataset": str(Path(ds.root).resolve())}, Path(out_dir) / "logs" / name, name, out)
        shutil.rmtree(images, ignore_errors=True)
        pre = "" if len(groups) == 1 else f"{name}."
        if why is None and not yaml_path.is_file():
            failed_output(out, name, f"wrote no {yaml_path.name}")
        elif why is None:
            try:
                calib.score_calibration(ds, out, name, pre, yaml_path, views, views, None)
                out.raw_files.append(yaml_path.name)
                continue
            except InputError as exc:  # an unreadable file is the method's failure
                failed_output(out, name, str(exc))
        for k in ("fx_rel_err", "fy_rel_err", "cx_abs_err_px", "cy_abs_err_px", "proj_diff_rms_px"):
            out.metrics[pre + k] = float("inf")  # a failed calibration: every error inf, never dropped
    return out
