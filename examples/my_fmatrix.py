"""A third-party fundamental-matrix estimator, as a user would bring one (docs/ci.md, "Your own
estimator"): SIFT keypoints, Lowe's ratio test, RANSAC to find the inliers, then the normalised
8-point algorithm on the inliers. It knows nothing of recon-eval: it reads two images and writes F.

    python examples/my_fmatrix.py IMAGE1 IMAGE2 F_OUT.txt [--transpose]
    python examples/my_fmatrix.py --matches MATCHES.npy F_OUT.txt INLIERS_OUT.npy

F_OUT.txt: 3x3 text, x2^T F x1 = 0 for OpenCV pixels x1 of IMAGE1 and x2 of IMAGE2. ``--transpose``
writes F^T, a planted bug for showing that a gate catches it. ``--matches``: given putative matches
(N, 4: x1 y1 x2 y2) instead of images, it skips SIFT and also writes its inlier mask (N,).
"""
import sys

import cv2
import numpy as np


def estimate_f(img1, img2, ratio=0.8):
    sift = cv2.SIFT_create()
    k1, d1 = sift.detectAndCompute(img1, None)
    k2, d2 = sift.detectAndCompute(img2, None)
    if d1 is None or d2 is None or len(k1) < 8 or len(k2) < 8:
        raise SystemExit(f"too few keypoints ({len(k1)}, {len(k2)})")
    pairs = cv2.BFMatcher(cv2.NORM_L2).knnMatch(d1, d2, k=2)
    good = [m for m, n in (p for p in pairs if len(p) == 2) if m.distance < ratio * n.distance]
    if len(good) < 8:
        raise SystemExit(f"too few matches after the ratio test ({len(good)})")
    return fit(np.float64([k1[m.queryIdx].pt for m in good]), np.float64([k2[m.trainIdx].pt for m in good]))[0]


def fit(x1, x2):
    """RANSAC (1 px) for the inliers, then the 8-point algorithm on them: (F, inlier mask)."""
    _, mask = cv2.findFundamentalMat(x1, x2, cv2.FM_RANSAC, 1.0, 0.999, 10000)
    inl = mask.ravel() != 0
    F, _ = cv2.findFundamentalMat(x1[inl], x2[inl], cv2.FM_8POINT)
    return F, inl


def main(argv):
    if argv[:1] == ["--matches"] and len(argv) == 4:
        m = np.load(argv[1])
        F, inl = fit(m[:, :2], m[:, 2:])
        np.savetxt(argv[2], F)
        np.save(argv[3], inl)
        return
    args = [a for a in argv if a != "--transpose"]
    if len(args) != 3:
        raise SystemExit(__doc__)
    img1, img2 = (cv2.imread(p, cv2.IMREAD_GRAYSCALE) for p in args[:2])
    if img1 is None or img2 is None:
        raise SystemExit(f"cannot read {args[0]} or {args[1]}")
    F = estimate_f(img1, img2)
    np.savetxt(args[2], F.T if "--transpose" in argv else F)


if __name__ == "__main__":
    main(sys.argv[1:])
