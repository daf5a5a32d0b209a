"""The Sampson distance of an F against OpenCV's ``cv2.sampsonDistance`` (which returns the squared
error, px^2): ``sampson_median_px`` is the median of the per-point distances, for even N the mean
of the two middle distances."""
from __future__ import annotations

import cv2
import numpy as np

from recon_eval.metrics.epipolar import fundamental_metrics


def test_sampson_rms_and_median_equal_opencv(agreement):
    rng = np.random.default_rng(0)
    F = rng.normal(size=(3, 3))
    U, s, Vt = np.linalg.svd(F)
    F = U @ np.diag([s[0], s[1], 0.0]) @ Vt
    x1 = rng.uniform(0, 640, (400, 2))  # even N
    x2 = rng.uniform(0, 480, (400, 2))
    sq = np.array([cv2.sampsonDistance(np.r_[a, 1.0][:, None], np.r_[b, 1.0][:, None], F) for a, b in zip(x1, x2)])
    r = fundamental_metrics(F, x1, x2)
    d = max(abs(r.sampson_median_px - np.median(np.sqrt(sq))), abs(r.sampson_rms_px - np.sqrt(np.mean(sq))))
    assert d < 1e-9 * max(1.0, np.median(np.sqrt(sq)))
    assert abs(r.sampson_median_px - np.sqrt(np.median(sq))) > 1e-6  # what it used to report
    agreement("epipolar.sampson", "sampson_median_px and sampson_rms_px, even N (px)",
              "OpenCV `cv2.sampsonDistance`", cv2.__version__, "400 random correspondences, rank-2 F", d)
