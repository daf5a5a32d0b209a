"""Kinds of a user's command (:mod:`recon_eval.runners.external`, ``KINDS``) over a sequence's
camera streams, scored as the built-in methods and scoring commands of their task (docs/ci.md,
"Your own estimator"):

* ``tracks``: per point-track stream: ``{images}`` its frames in order, ``{queries}`` an (N, 3)
  ``.npy`` of TAP-Vid query points ``t y x`` (frame index, OpenCV pixels) -> ``{out}`` a
  pickle-free ``.npz`` with ``tracks_xy`` (N, T, 2) px and ``occluded`` (N, T) bool; TAP-Vid's
  metrics at 256 x 256, query mode ``first``, as ``opencv-lk-tapvid`` and ``recon-eval tracks``.
* ``trajectory``: per camera stream (a rig member, else a spec camera; the streams of the TUM
  export): ``{images}`` its frames in time order, ``{times}`` a text file of ``timestamp image``
  lines (the view's ``time_s``, else its frame index, as the TUM export), ``{k}`` / ``{dist}`` the
  camera's K (3x3) and OpenCV distortion (text) -> ``{out}`` a TUM trajectory (``timestamp tx ty
  tz qx qy qz qw``, world_from_cam); associated by timestamp (0.01 s) and scored as ``recon-eval
  poses`` with its defaults (APE after Sim(3), RPE over consecutive frames).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.align import umeyama
from recon_eval.metrics.poses import Poses, ape, registration_ratio, rpe
from recon_eval.metrics.tapvid import TAPVID_EVAL_SIZE
from recon_eval.readers.tracks import read_tracks
from recon_eval.readers.tum import TumTrajectory, associate, read_tum
from recon_eval.runners.common import RunOutput
from recon_eval.runners.external import failed_output, invoke
from recon_eval.tasks.headlines import tracks_headline, trajectory_headline
from recon_eval.tasks.tracks import score_streams
from scenegen.dataset.layout import check_name, check_view_name

#: The headline errors of a trajectory that cannot be aligned: inf (its registration ratio stands).
FAILED = ("max_rot_err_deg", "median_rot_err_deg", "ape_trans_rmse_m", "rpe_trans_rmse_m")
#: TUM timestamp association, seconds (``recon-eval poses --max-time-diff``'s default).
MAX_TIME_DIFF_S = 0.01


def tracks(ds, out_dir, options) -> RunOutput:
    """The ``tracks`` kind (module docstring)."""
    streams = ds.track_streams()
    out, predictions = RunOutput(), {}
    root = str(Path(ds.root).resolve())
    for stream, frames in streams.items():
        name = check_name("stream", stream)
        truth = ds.tracks_truth(stream)
        n, t = truth.occluded.shape
        d = Path(out_dir) / name
        d.mkdir(parents=True, exist_ok=True)
        queries, path = d / "queries.npy", d / "tracks.npz"
        np.save(queries, np.asarray(truth.query_points, np.float64))
        path.unlink(missing_ok=True)
        values = {"images": [str(ds.image_path(v).resolve()) for v in frames], "queries": str(queries.resolve()),
                  "out": str(path.resolve()), "dataset": root}
        pred = None
        if invoke(options, values, d, name, out) is None:
            try:
                pred = read_tracks(path, n, t)
                out.raw_files.append(f"{name}/tracks.npz")
            except InputError as exc:  # the method's failure: every point lost
                failed_output(out, name, str(exc))
        predictions[stream] = pred if pred is not None else (np.zeros((n, t, 2)), np.ones((n, t), bool))
    res = score_streams(ds, streams, lambda s, n, t: predictions[s], query_mode="first", eval_size=TAPVID_EVAL_SIZE)
    out.results["tapvid"] = res
    out.metrics.update(tracks_headline(res))
    return out


def camera_streams(ds) -> dict:
    """{stream: [(timestamp, view), ...] in time order}: the TUM export's streams."""
    streams: dict = {}
    for v in ds.views:
        info = ds.view_info(v)
        key = f"{info['rig']}_{info['rig_member']}" if info.get("rig") else str(info["camera_name"])
        streams.setdefault(check_name("stream", key), []).append((float(info.get("time_s", info["frame_index"])), v))
    return {k: sorted(items) for k, items in streams.items()}


def trajectory(ds, out_dir, options) -> RunOutput:
    """The ``trajectory`` kind (module docstring)."""
    streams = {k: items for k, items in camera_streams(ds).items() if len(items) >= 3}
    if not streams:
        raise NotApplicable(f"{ds.root}: no camera stream of 3 or more frames (a trajectory needs a sequence)")
    out = RunOutput()
    root = str(Path(ds.root).resolve())
    for stream, items in streams.items():
        d = Path(out_dir) / stream
        d.mkdir(parents=True, exist_ok=True)
        images = [str(ds.image_path(v).resolve()) for _, v in items]
        times = d / "times.txt"
        times.write_text("".join(f"{ts:.6f} {im}\n" for (ts, _), im in zip(items, images)))
        cam, _ = ds.camera(items[0][1])
        K, D = cam.to_opencv()
        np.savetxt(d / "K.txt", K, fmt="%.17g")
        np.savetxt(d / "dist.txt", np.reshape(D, (1, -1)), fmt="%.17g")
        path = d / "trajectory.txt"
        path.unlink(missing_ok=True)
        values = {"images": images, "times": str(times.resolve()), "camera": stream, "k": str((d / "K.txt").resolve()),
                  "dist": str((d / "dist.txt").resolve()), "out": str(path.resolve()), "dataset": root}
        names = tuple(check_view_name(v) for _, v in items)
        poses = [ds.camera(v)[1] for _, v in items]
        gt = Poses(names, np.stack([p.R for p in poses]), np.stack([p.t for p in poses]))
        try:  # Sim(3) on the camera centres: a straight or static truth path leaves it undetermined
            umeyama(gt.centers_world, gt.centers_world, with_scale=True)
        except InputError as exc:
            raise NotApplicable(f"{ds.root}: stream {stream!r}: the truth trajectory cannot anchor a Sim(3) "
                                f"alignment ({exc})") from None
        truth = TumTrajectory(np.array([ts for ts, _ in items]), gt)
        est = Poses(names, np.full((len(names), 3, 3), np.nan), np.full((len(names), 3), np.nan))
        if invoke(options, values, d, stream, out) is None:
            try:
                est = associate(read_tum(path), truth, MAX_TIME_DIFF_S)
                out.raw_files.append(f"{stream}/trajectory.txt")
            except InputError as exc:  # an unreadable trajectory: every frame unregistered
                failed_output(out, stream, str(exc))
        pre = "" if len(streams) == 1 else f"{stream}."
        try:
            a, r = ape(est, gt), rpe(est, gt)
        except InputError as exc:  # fewer than 3 registered frames, or a degenerate estimate: failed
            failed_output(out, stream, f"alignment: {exc}")
            out.metrics.update({pre + k: float("inf") for k in FAILED})
            out.metrics[pre + "registration_ratio"] = registration_ratio(est, gt)
            continue
        out.results[f"{stream}.ape"] = a
        out.results[f"{stream}.rpe"] = r
        out.metrics.update({pre + k: v for k, v in trajectory_headline(a, r, "sim3").items()})
    return out
