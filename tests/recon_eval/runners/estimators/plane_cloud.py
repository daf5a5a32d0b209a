"""A cloud "estimator" for the tests: a 5 cm grid over [-1, 1]^2 on the plane z = 0 (the analytic
plane dataset's surface), and one point 0.5 m above it, as an ASCII PLY. Usage: plane_cloud.py OUT.ply"""
import sys

import numpy as np

g = np.linspace(-1.0, 1.0, 41)
pts = np.c_[np.stack(np.meshgrid(g, g), -1).reshape(-1, 2), np.zeros(41 * 41)]
pts = np.vstack([pts, [0.0, 0.0, 0.5]])
head = f"ply\nformat ascii 1.0\nelement vertex {len(pts)}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
with open(sys.argv[1], "w") as f:
    f.write(head + "".join(f"{x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in pts))
