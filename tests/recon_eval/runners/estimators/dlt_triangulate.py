"""A user's triangulator that knows nothing of recon-eval: cv2.triangulatePoints on each pair of a
triangulation task folder. Usage: dlt_triangulate.py TASK OUT_DIR"""
import sys
from pathlib import Path

import cv2
import numpy as np

task, out = Path(sys.argv[1]), Path(sys.argv[2])
for pair in sorted(p for p in task.iterdir() if (p / "observations.txt").is_file()):
    P1, P2 = np.loadtxt(pair / "P1.txt"), np.loadtxt(pair / "P2.txt")
    obs = np.loadtxt(pair / "observations.txt", ndmin=2)
    X = cv2.triangulatePoints(P1, P2, obs[:, :2].T.copy(), obs[:, 2:].T.copy())
    np.savetxt(out / f"{pair.name}.txt", (X[:3] / X[3]).T, fmt="%.17g")
