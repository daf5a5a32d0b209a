"""A trajectory "estimator" for the tests: the dataset's camera poses of the frames listed in TIMES
(``timestamp image`` lines; the image's stem is the view), scaled by SCALE about the origin (a
Sim(3) alignment undoes it), written as TUM world_from_cam. Usage: true_trajectory.py DATASET TIMES OUT SCALE"""
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from scenegen.dataset import Dataset

d, lines, out, scale = Dataset(sys.argv[1]), Path(sys.argv[2]).read_text().splitlines(), sys.argv[3], float(sys.argv[4])
rows = []
for line in lines:
    ts, image = line.split(" ", 1)
    _, cam_from_world = d.camera(Path(image).stem)
    world_from_cam = cam_from_world.inverse()
    rows.append([float(ts), *(scale * world_from_cam.t), *Rotation.from_matrix(world_from_cam.R).as_quat()])
np.savetxt(out, rows, fmt="%.17g")
