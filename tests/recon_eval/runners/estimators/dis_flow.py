"""A user's flow estimator that knows nothing of recon-eval: OpenCV DIS (preset medium) on the grey
images, written as a Middlebury .flo by hand. Usage: dis_flow.py IMAGE1 IMAGE2 OUT.flo"""
import sys

import cv2
import numpy as np

a, b = (cv2.imread(p, cv2.IMREAD_GRAYSCALE) for p in sys.argv[1:3])
flow = cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM).calc(a, b, None)
with open(sys.argv[3], "wb") as f:
    f.write(b"PIEH" + np.array([flow.shape[1], flow.shape[0]], "<i4").tobytes() + flow.astype("<f4").tobytes())
