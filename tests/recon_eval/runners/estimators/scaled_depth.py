"""A depth "estimator" for the tests: the dataset's truth z-depth times SCALE (a known error:
abs_rel = |SCALE - 1| without alignment, 0 with median scaling). Usage: scaled_depth.py DATASET VIEW OUT.npy SCALE"""
import sys

import numpy as np

from scenegen.dataset import Dataset

root, view, out, scale = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
np.save(out, Dataset(root).truth(view)["depth_z"].astype(np.float64) * scale)
