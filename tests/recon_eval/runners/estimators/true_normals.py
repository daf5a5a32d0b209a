"""A normals "estimator" for the tests: the dataset's truth normals of the set's first image, in
DiLiGenT's axes (x right, y up, z toward the camera). Usage: true_normals.py DATASET OUT.npy IMAGE..."""
import sys
from pathlib import Path

import numpy as np

from scenegen.dataset import Dataset

root, out, first = sys.argv[1], sys.argv[2], Path(sys.argv[3]).stem
n = Dataset(root).truth(first)["normals_cam"].astype(np.float64)
np.save(out, n * np.array([1.0, -1.0, -1.0]))  # OpenCV camera axes -> DiLiGenT's
