"""A DLT for the tests: recon_eval's normalised linear DLT on u v X Y Z rows, NaN below its minimum
(6 points, not coplanar), as dlt-linear does. Usage: linear_dlt.py POINTS.npy OUT.txt"""
import sys

import numpy as np

from recon_eval.metrics.dlt import dlt_projection
from recon_eval.tasks.board_truth import is_three_dimensional

p = np.load(sys.argv[1])
x, X = p[:, :2], p[:, 2:]
ok = len(x) >= 6 and is_three_dimensional(X)
np.savetxt(sys.argv[2], dlt_projection(X, x) if ok else np.full((3, 4), np.nan), fmt="%.17g")
