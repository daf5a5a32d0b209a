"""A point tracker for the tests: recon_eval's LK chain (the opencv-lk-tapvid baseline) on the frames
as read from disk. Usage: lk_tracks.py QUERIES.npy OUT.npz FRAME..."""
import sys

import cv2
import numpy as np

from recon_eval.runners.tracking import lk_tracks

queries, out, frames = sys.argv[1], sys.argv[2], sys.argv[3:]
tracks, occluded = lk_tracks([cv2.cvtColor(cv2.imread(f), cv2.COLOR_BGR2GRAY) for f in frames], np.load(queries))
np.savez(out, tracks_xy=tracks.astype(np.float32), occluded=occluded)
