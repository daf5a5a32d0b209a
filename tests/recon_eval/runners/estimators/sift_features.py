"""A user's keypoint pipeline that knows nothing of recon-eval: SIFT with default parameters on the
grey images, brute-force mutual nearest neighbours, written in recon_eval's feature format.
Usage: sift_features.py IMAGES_DIR PAIRS_TXT OUT_DIR"""
import sys
from pathlib import Path

import cv2
import numpy as np

images, pairs, out = Path(sys.argv[1]), Path(sys.argv[2]).read_text().split("\n"), Path(sys.argv[3])
(out / "keypoints").mkdir(parents=True, exist_ok=True)
(out / "matches").mkdir(exist_ok=True)
des = {}
for png in sorted(images.glob("*.png")):
    kps, des[png.stem] = cv2.SIFT_create().detectAndCompute(cv2.imread(str(png), cv2.IMREAD_GRAYSCALE), None)
    rows = np.array([(k.pt[0], k.pt[1], k.size, k.angle, k.response) for k in kps]).reshape(-1, 5)
    np.savetxt(out / "keypoints" / f"{png.stem}.txt", rows, fmt="%.9g")
for line in pairs:
    if line.strip():
        i, j = line.split()
        ms = cv2.BFMatcher(cv2.NORM_L2, crossCheck=True).match(des[i], des[j])
        rows = np.array(sorted((m.queryIdx, m.trainIdx) for m in ms)).reshape(-1, 2)
        np.savetxt(out / "matches" / f"{i}__{j}.txt", rows, fmt="%d")
