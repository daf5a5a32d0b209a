"""A two-view "estimator" for the tests: the truth E or F of the pair from the dataset's cameras
(E = [t]x R of cam2_from_cam1; F = K2^-T E K1^-1), or NaN with --nan.
Usage: true_two_view.py E|F DATASET VIEW1 VIEW2 OUT [--nan]"""
import sys

import numpy as np

from scenegen.dataset import Dataset

what, root, v1, v2, out = sys.argv[1:6]
d = Dataset(root)
(c1, p1), (c2, p2) = d.camera(v1), d.camera(v2)
rel = p2 @ p1.inverse()
t = rel.t
E = np.array([[0, -t[2], t[1]], [t[2], 0, -t[0]], [-t[1], t[0], 0]]) @ rel.R
M = E if what == "E" else np.linalg.inv(c2.K).T @ E @ np.linalg.inv(c1.K)
np.savetxt(out, np.full((3, 3), np.nan) if "--nan" in sys.argv else M / np.linalg.norm(M))
