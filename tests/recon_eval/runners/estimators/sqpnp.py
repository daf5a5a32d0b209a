"""A user's PnP that knows nothing of recon-eval: cv2.solvePnP (SQPnP) on u v X Y Z rows, written as
cam_from_world [R | t]. Usage: sqpnp.py POINTS.npy K.txt DIST.txt OUT.txt"""
import sys

import cv2
import numpy as np

p, K, D = np.load(sys.argv[1]), np.loadtxt(sys.argv[2]), np.loadtxt(sys.argv[3], ndmin=1)
X, x = np.ascontiguousarray(p[:, 2:]), np.ascontiguousarray(p[:, :2])  # OpenCV wants contiguous rows
ok, rvec, tvec = cv2.solvePnP(X, x, K, D, flags=cv2.SOLVEPNP_SQPNP)
np.savetxt(sys.argv[4], np.c_[cv2.Rodrigues(rvec)[0], tvec.ravel()], fmt="%.17g")
