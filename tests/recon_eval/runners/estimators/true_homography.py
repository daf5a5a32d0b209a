"""A homography "estimator" for the tests: the dataset's truth H of the plane (crossview/twoview),
or its transpose with --transpose. Usage: true_homography.py DATASET VIEW1 VIEW2 PLANE OUT [--transpose]"""
import json
import sys
from pathlib import Path

import numpy as np

root, v1, v2, plane, out = sys.argv[1:6]
H = np.array(json.loads((Path(root) / "crossview" / "twoview" / v1 / f"{v2}.json").read_text())["homographies"][plane]["H"])
np.savetxt(out, H.T if "--transpose" in sys.argv else H, fmt="%.17g")
