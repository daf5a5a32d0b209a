"""Triangulation tasks: camera pairs of a dataset with noisy truth correspondences, written as a
self-contained folder so that any triangulator can be run on it and scored against the truth
points (``recon-eval triangulation-task`` writes one, ``recon-eval triangulation`` scores an
answer, the ``opencv-triangulate`` runner does both with ``cv2.triangulatePoints``).

Folder layout (``<pair>`` = ``<view1>__<view2>``)::

    TASK/task.json                     format, version, settings; per pair: views, K, cam_from_world,
                                       files, n_points
    TASK/<pair>/P1.txt, P2.txt         P = K [R | t] of view 1 / view 2 (3 rows of 4 numbers)
    TASK/<pair>/observations.txt       N rows "x1 y1 x2 y2": undistorted OpenCV pixels of P1 / P2
    TASK/truth/<pair>.txt              N rows "X Y Z": the truth points (world frame, metres)

Numbers are written with 17 significant digits (float64 round trip). The truth points are the
hit points of view 1's pixel centres (the dataset's float32 truth read as float64) that view 2
sees (the dataset's ray-cast visibility, :meth:`DatasetTruth.correspondences`: the pair needs
correspondence truth), ``count`` of them drawn uniformly (seeded). Their noise-free observations
are their projections through P1 and P2, so a perfect triangulator recovers them to float64 rounding; for a distorted camera these are undistorted
pixels, what the camera model's exact inverse gives for the distorted pixel. Then Gaussian noise
of ``sigma_px`` per coordinate (:func:`recon_eval.metrics.triangulation.noisy_observations`). Selection and
noise are seeded per pair, :func:`scenegen.geometry.seeds.rng` ``(seed, pair, 0)`` and
:func:`scenegen.geometry.seeds.seed32` ``(seed, pair, 1)``: the same pair gets the same points and
noise whatever the other pairs are, and the points do not depend on sigma.

Answer (:func:`read_estimates`): ``EST_DIR/<pair>.txt``, one ``X Y Z`` row (world frame, metres)
per observation row, in order (``#`` comments and blank lines skipped). ``nan nan nan`` marks a
point not triangulated; rows missing at the end of a file, and a missing file, are failures too:
error inf (metrics.md, "Triangulation").
"""
from __future__ import annotations

import io
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.dlt import project_with_P
from recon_eval.metrics.triangulation import (noisy_observations, pool_scores, projection_matrix, score_triangulation,
                                              triangulate_opencv)
from recon_eval.readers.rows import read_projection_matrix, read_rows
from recon_eval.report.document import write_json_atomic
from scenegen.dataset.files import atomic_write_bytes
from scenegen.dataset.layout import CROSSVIEW_INDEX, check_name, check_rel_path
from scenegen.geometry import seeds
from scenegen.geometry.pose import camera_center
from scenegen.geometry.twoview import ZERO_BASELINE_M

TASK_FORMAT = "recon-eval-triangulation-task"
TASK_VERSION = 1
#: Truth points per pair when the caller does not say.
DEFAULT_COUNT = 2000


@dataclass(frozen=True)
class TaskPair:
    """One camera pair of a task. Poses cam_from_world, pixels undistorted OpenCV pixels."""

    name: str
    view1: str
    view2: str
    P1: np.ndarray  # (3, 4) K1 [R1 | t1]
    P2: np.ndarray  # (3, 4)
    observations: np.ndarray  # (N, 4) x1 y1 x2 y2, px
    points_true: np.ndarray  # (N, 3) world, metres
    cam1_from_world: tuple  # (R (3, 3), t (3,))
    cam2_from_world: tuple


def pair_name(view1: str, view2: str) -> str:
    return f"{view1}__{view2}"


def visible_truth_points(ds, view1: str, view2: str, count: int, seed: int = 0) -> np.ndarray:
    """Up to ``count`` truth points (N, 3) of ``view1``'s pixel centres that ``view2`` sees, drawn
    uniformly without replacement (seeded), in the row-major order of their view-1 pixels."""
    cam1, _ = ds.camera(view1)
    n_all = cam1.width * cam1.height  # every valid pixel: points_at_pixels then keeps them all
    x1, X = ds.points_at_pixels(view1, max_points=n_all)
    x1_vis, _ = ds.correspondences(view1, view2, max_points=n_all)  # the same pixels, filtered

    def key(x):
        return np.rint(x[:, 1]).astype(np.int64) * cam1.width + np.rint(x[:, 0]).astype(np.int64)

    idx = np.flatnonzero(np.isin(key(x1), key(x1_vis)))
    rng = seeds.rng(int(seed), pair_name(view1, view2), 0)
    pick = np.sort(rng.permutation(len(idx))[:count])
    return X[idx[pick]]


def build_pair(ds, view1: str, view2: str, sigma_px: float, count: int = DEFAULT_COUNT, seed: int = 0) -> TaskPair:
    """The task pair (view1, view2) of the dataset (module docstring)."""
    if view1 == view2:
        raise InputError(f"pair {view1}:{view2}: the two views must differ")
    name = pair_name(view1, view2)
    (c1, p1), (c2, p2) = ds.camera(view1), ds.camera(view2)
    X = visible_truth_points(ds, view1, view2, count, seed)
    if len(X) == 0:
        raise InputError(f"{ds.root}: views {view1!r} and {view2!r} share no visible truth point")
    P1, P2 = projection_matrix(c1.K, p1.R, p1.t), projection_matrix(c2.K, p2.R, p2.t)
    x = np.hstack([project_with_P(P1, X), project_with_P(P2, X)])  # (N, 4)
    noise_seed = seeds.seed32(int(seed), name, 1)
    x = noisy_observations(x.reshape(-1, 2), sigma_px, seed=noise_seed).reshape(-1, 4)
    return TaskPair(name, view1, view2, P1, P2, x, X, (p1.R.copy(), p1.t.copy()), (p2.R.copy(), p2.t.copy()))


def baseline_m(ds, view1: str, view2: str) -> float:
    """Distance (metres) between the two views' camera centres."""
    (_, p1), (_, p2) = ds.camera(view1), ds.camera(view2)
    return float(np.linalg.norm(camera_center(p1) - camera_center(p2)))


def dataset_pairs(ds, pairs=None) -> tuple[list, list]:
    """``([(view1, view2)], skipped)``: the pairs given as ``"V1:V2"`` strings, else those of the
    dataset's crossview/index.json. Two views with one camera centre (a roll about the optical
    axis, an illumination pair; closer than ``scenegen.geometry.twoview.ZERO_BASELINE_M``) have
    no triangulation: such a pair given by name is an error, one from the index is left out and
    listed in ``skipped``."""
    if pairs:
        out = []
        for s in pairs:
            parts = s.split(":")
            if len(parts) != 2 or not all(parts):
                raise InputError(f"--pairs: expected VIEW1:VIEW2, got {s!r}")
            v1, v2 = ds.check_view(parts[0]), ds.check_view(parts[1])
            if v1 != v2 and baseline_m(ds, v1, v2) < ZERO_BASELINE_M:  # (a view with itself: build_pair)
                raise InputError(f"--pairs {s}: the two views share one camera centre (zero baseline): "
                                 "nothing can be triangulated")
            out.append((v1, v2))
        return out, []
    try:
        index_pairs = ds.crossview_pairs()
    except NotApplicable as exc:
        raise NotApplicable(f"{exc}; no view pairs given either (--pairs V1:V2 ...)") from None
    if not index_pairs:
        raise InputError(f"{ds.root / CROSSVIEW_INDEX}: pairs: empty, and no view pairs given (--pairs V1:V2 ...)")
    out, skipped = [], []
    for i, j in index_pairs:
        v1, v2 = ds.check_view(i), ds.check_view(j)
        (skipped if baseline_m(ds, v1, v2) < ZERO_BASELINE_M else out).append((v1, v2))
    if not out:
        raise InputError(f"{ds.root / CROSSVIEW_INDEX}: pairs: every pair has a zero baseline "
                         "(one camera centre): nothing can be triangulated")
    return out, skipped


def _table_bytes(a: np.ndarray, header: str) -> bytes:
    buf = io.StringIO()
    np.savetxt(buf, np.asarray(a, np.float64), fmt="%.17g", header=header)
    return buf.getvalue().encode("utf-8")


def write_task(task_dir, pairs: list, settings: dict) -> Path:
    """Write the task folder (module docstring); ``settings`` (dataset, sigma_px, seed, count...) go
    to task.json as they are. Every file is written atomically. Returns the task.json path."""
    root = Path(task_dir)
    root.mkdir(parents=True, exist_ok=True)
    entries = []
    for tp in pairs:
        files = {"P1": f"{tp.name}/P1.txt", "P2": f"{tp.name}/P2.txt",
                 "observations": f"{tp.name}/observations.txt", "truth": f"truth/{tp.name}.txt"}
        for k, v in (("P1", tp.view1), ("P2", tp.view2)):
            atomic_write_bytes(root / files[k], _table_bytes(
                getattr(tp, k), f"P = K [R | t] of view {v} (cam_from_world; undistorted OpenCV pixels)"))
        atomic_write_bytes(root / files["observations"], _table_bytes(
            tp.observations, f"x1 y1 x2 y2: undistorted OpenCV pixels of P1 ({tp.view1}) and P2 ({tp.view2}); "
                             f"sigma {settings.get('sigma_px')} px per coordinate"))
        atomic_write_bytes(root / files["truth"], _table_bytes(
            tp.points_true, "X Y Z: truth points (world frame, metres), one per observation row; for scoring"))
        entries.append({
            "name": tp.name, "view1": tp.view1, "view2": tp.view2, "n_points": int(len(tp.points_true)),
            "files": files,
            "cam1_from_world": {"R": tp.cam1_from_world[0].tolist(), "t": tp.cam1_from_world[1].tolist()},
            "cam2_from_world": {"R": tp.cam2_from_world[0].tolist(), "t": tp.cam2_from_world[1].tolist()},
        })
    doc = {"format": TASK_FORMAT, "version": TASK_VERSION, **settings,
           "answer": "EST_DIR/<name>.txt: one 'X Y Z' row (world frame, metres) per observations.txt row, in "
                     "order; 'nan nan nan' for a point not triangulated. truth/ is the scorer's: do not read it.",
           "pairs": entries}
    write_json_atomic(root / "task.json", doc)
    return root / "task.json"


def read_task(task_dir) -> tuple[dict, list]:
    """(task.json document, [TaskPair]) of a task folder; every problem names the file."""
    root = Path(task_dir)
    jpath = root / "task.json"
    if not jpath.is_file():
        raise InputError(f"{root}: not a triangulation task (no task.json; write one with recon-eval "
                         f"triangulation-task)")
    try:
        doc = json.loads(jpath.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{jpath}: invalid JSON ({exc})") from None
    except RecursionError:
        raise InputError(f"{jpath}: invalid JSON (nested too deeply)") from None
    if not isinstance(doc, dict) or doc.get("format") != TASK_FORMAT:
        raise InputError(f"{jpath}: format: expected {TASK_FORMAT!r}")
    if doc.get("version") != TASK_VERSION:
        raise InputError(f"{jpath}: version: expected {TASK_VERSION}, got {doc.get('version')!r}")
    pairs = []
    for k, e in enumerate(doc.get("pairs") or []):
        where = f"{jpath}: pairs[{k}]"
        try:
            name, files, n = check_name("pair", e["name"]), e["files"], int(e["n_points"])
            files = {f: check_rel_path(files[f]) for f in ("P1", "P2", "observations", "truth")}  # no '..'
            cams = [(np.asarray(e[c]["R"], np.float64), np.asarray(e[c]["t"], np.float64))
                    for c in ("cam1_from_world", "cam2_from_world")]
            paths = {f: root / files[f] for f in ("P1", "P2", "observations", "truth")}
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
            raise InputError(f"{where}: missing or malformed field ({type(exc).__name__}: {exc})") from None
        if any(R.shape != (3, 3) or t.shape != (3,) for R, t in cams):
            raise InputError(f"{where}: cam*_from_world: expected R 3x3 and t 3 numbers")
        obs = read_rows(paths["observations"], "x1 y1 x2 y2", (4,))
        X = read_rows(paths["truth"], "X Y Z", (3,))
        for rows, f in ((obs, "observations"), (X, "truth")):
            if len(rows) != n:
                raise InputError(f"{paths[f]}: {len(rows)} rows, task.json says n_points = {n}")
        pairs.append(TaskPair(name, str(e.get("view1")), str(e.get("view2")),
                              read_projection_matrix(paths["P1"]), read_projection_matrix(paths["P2"]),
                              np.asarray([r.values for r in obs]).reshape(-1, 4),
                              np.asarray([r.values for r in X]).reshape(-1, 3), cams[0], cams[1]))
    if not pairs:
        raise InputError(f"{jpath}: pairs: the task has no camera pair")
    return doc, pairs


def reference_points(tp: TaskPair) -> np.ndarray:
    """The reference method on a task pair: ``cv2.triangulatePoints`` (N, 3)."""
    return triangulate_opencv(tp.P1, tp.P2, tp.observations[:, :2], tp.observations[:, 2:])


def write_points(path, points) -> None:
    """An answer file: one ``X Y Z`` row per point (17 significant digits), atomically."""
    atomic_write_bytes(path, _table_bytes(points, "X Y Z: triangulated points (world frame, metres)"))


def read_estimates(est_dir, pairs: list) -> tuple[dict, dict]:
    """({pair name: (N, 3) points, failures inf}, notes) from ``EST_DIR/<pair>.txt`` (module
    docstring). Notes list the missing files and the files with missing rows. A row with other
    than 3 numbers, more rows than observations, or no answer file at all is an error."""
    d = Path(est_dir)
    if not d.is_dir():
        raise InputError(f"{d}: no such folder (expected <pair>.txt answer files)")
    out, notes = {}, {"missing_files": [], "short_files": {}}
    for tp in pairs:
        p = d / f"{tp.name}.txt"
        n = len(tp.points_true)
        X = np.full((n, 3), np.inf)
        if not p.is_file():
            notes["missing_files"].append(p.name)
        else:
            rows = read_rows(p, "X Y Z", (3,))
            if len(rows) > n:
                raise InputError(f"{p}:{rows[n].line}: more rows than observations ({n} in "
                                 f"{tp.name}/observations.txt)")
            if rows:
                X[: len(rows)] = np.asarray([r.values for r in rows])
            if len(rows) < n:
                notes["short_files"][p.name] = {"rows": len(rows), "observations": n}
        out[tp.name] = np.where(np.all(np.isfinite(X), axis=1)[:, None], X, np.inf)
    if len(notes["missing_files"]) == len(pairs):
        raise InputError(f"{d}: no answer file for any pair (expected {', '.join(tp.name + '.txt' for tp in pairs[:4])}"
                         f"{' ...' if len(pairs) > 4 else ''})")
    return out, notes


def bin_label(b) -> str:
    """``bin_<lo>-<hi>deg`` of an AngleBin: the key of a bin in reports and run metrics."""
    return f"bin_{b.lo_deg:g}-{b.hi_deg:g}deg"


def bin_curve(score) -> tuple:
    """(median_angle_deg, lo_deg, hi_deg, median_m, median_rel), each (K,), of the non-empty angle
    bins of a TriangulationScore: a curve of :func:`recon_eval.report.plots.triangulation_angle_figure`."""
    b = [x for x in score.bins if x.n]
    return tuple(np.array([getattr(x, f) for x in b], np.float64)
                 for f in ("median_angle_deg", "lo_deg", "hi_deg", "median_m", "median_rel"))


def score_task(pairs: list, estimates: dict) -> dict:
    """{pair name: TriangulationScore} plus ``"all_pairs"``: the pooled score
    (:func:`recon_eval.metrics.triangulation.pool_scores`)."""
    res = {tp.name: score_triangulation(estimates[tp.name], tp.points_true, tp.cam1_from_world, tp.cam2_from_world)
           for tp in pairs}
    res["all_pairs"] = pool_scores(list(res.values()))
    return res
