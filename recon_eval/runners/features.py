"""OpenCV keypoint detectors and descriptors, matched by brute force with mutual nearest neighbours,
scored on the cross-view pairs of a dataset (docs/features.md).

Protocol (D2-Net, Dusmanu et al. 2019, on HPatches): every view of a ``crossview/index.json`` pair
is converted to 8-bit grey (:func:`scenegen.geometry.color.to_grey8`); the detector-descriptor runs
**out of the box** (``cv2.SIFT_create()``, ``cv2.ORB_create()``, ``cv2.AKAZE_create()``,
``cv2.BRISK_create()`` with their default parameters: no parameter is set, so ORB keeps at most
its default 500 keypoints); descriptors of view i and view j are matched by ``cv2.BFMatcher`` with
``crossCheck=True`` (mutual nearest neighbours, no ratio test): L2 for SIFT, Hamming for the binary
descriptors (ORB, AKAZE's MLDB, BRISK).

Raw output, in recon_eval's feature format (:mod:`recon_eval.readers.features`):
``keypoints/<view>.txt`` (``x y size angle response``, OpenCV pixels, float32 values written
exactly) and ``matches/<i>__<j>.txt`` (``index_i index_j``). The scores are computed from those
files read back (:mod:`recon_eval.tasks.feature_eval`).
"""
from __future__ import annotations

import io

import cv2
import numpy as np

from recon_eval.readers.features import KEYPOINTS_DIR, MATCHES_DIR, match_stem, read_feature_files
from recon_eval.runners.common import RunOutput, crossview_pairs, out_path
from recon_eval.tasks.feature_eval import DEFAULT_EPS_PX, evaluate_features, headline_metrics, results_dict
from scenegen.dataset.files import atomic_write_bytes
from scenegen.geometry.color import to_grey8

#: detector name -> OpenCV factory (called without arguments: default parameters)
CV_FACTORIES = {"sift": "SIFT_create", "orb": "ORB_create", "akaze": "AKAZE_create", "brisk": "BRISK_create"}
#: Text format of the keypoint columns: 9 significant digits round-trip float32 exactly.
KEYPOINT_FMT = "%.9g"


def _detector(name: str):
    return getattr(cv2, CV_FACTORIES[name])()


def _norm(name: str) -> int:
    return cv2.NORM_L2 if name == "sift" else cv2.NORM_HAMMING


def detect(name: str, image) -> tuple[np.ndarray, np.ndarray | None]:
    """Keypoint rows (N, 5) ``x y size angle response`` and descriptors (N, D) (None when N = 0)
    of one image, by OpenCV detector ``name`` with default parameters."""
    kps, des = _detector(name).detectAndCompute(to_grey8(image), None)
    rows = np.array([(k.pt[0], k.pt[1], k.size, k.angle, k.response) for k in kps], np.float64).reshape(-1, 5)
    return rows, des


def match_mutual(name: str, des_i, des_j) -> np.ndarray:
    """(M, 2) int64 ``index_i index_j``: brute-force mutual nearest neighbours (cross-check)."""
    if des_i is None or des_j is None or len(des_i) == 0 or len(des_j) == 0:
        return np.zeros((0, 2), np.int64)
    ms = cv2.BFMatcher(_norm(name), crossCheck=True).match(des_i, des_j)
    return np.array(sorted((m.queryIdx, m.trainIdx) for m in ms), np.int64).reshape(-1, 2)


def _write_txt(path, rows, fmt: str, header: str) -> None:
    """np.savetxt, written atomically (a reader never sees half a file)."""
    buf = io.StringIO()
    np.savetxt(buf, rows, fmt=fmt, header=header)
    atomic_write_bytes(path, buf.getvalue().encode())


def run(ds, out_dir, options) -> RunOutput:
    name = options["detector"]
    pairs = list(crossview_pairs(ds))
    views = list(dict.fromkeys(v for p in pairs for v in p))
    out = RunOutput()
    des, counts = {}, {}
    head = (f"x y size angle response: cv2.{CV_FACTORIES[name]}() keypoints (OpenCV {cv2.__version__}); "
            "OpenCV pixels, centre of the top-left pixel = (0, 0)")
    for v in views:
        rows, des[v] = detect(name, ds.image(v))
        rel = f"{KEYPOINTS_DIR}/{v}.txt"
        _write_txt(out_path(out_dir, rel), rows, KEYPOINT_FMT, head)
        out.raw_files.append(rel)
        counts[v] = len(rows)
    n_matches = {}
    for i, j in pairs:
        mt = match_mutual(name, des[i], des[j])
        rel = f"{MATCHES_DIR}/{match_stem(i, j)}.txt"
        _write_txt(out_path(out_dir, rel), mt, "%d",
                   f"index_i index_j: rows of keypoints/{i}.txt and keypoints/{j}.txt (BFMatcher, crossCheck)")
        out.raw_files.append(rel)
        n_matches[match_stem(i, j)] = len(mt)
    files = read_feature_files(out_dir, views, pairs)  # score what was written
    ev = evaluate_features(ds, files.keypoints, files.matches, pairs, DEFAULT_EPS_PX)
    out.results = results_dict(ev, files)
    out.metrics = headline_metrics(ev)
    out.notes = {"detector": f"cv2.{CV_FACTORIES[name]}() (default parameters)",
                 "matcher": f"cv2.BFMatcher({'NORM_L2' if name == 'sift' else 'NORM_HAMMING'}, crossCheck=True)",
                 "eps_px": DEFAULT_EPS_PX, "keypoints_per_view": counts, "matches_per_pair": n_matches}
    return out
