"""A reconstruction's own reprojection error and track length against pycolmap (a dev dependency):
``Reconstruction.update_point_3d_errors`` then ``compute_mean_reprojection_error``,
``compute_mean_track_length``, ``compute_mean_observations_per_reg_image``, on a text model and
its binary copy, read by recon_eval's COLMAP readers."""
from __future__ import annotations

import numpy as np
import pycolmap
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.cli.poses import colmap_model_stats

CAMS = {1: ("SIMPLE_RADIAL", [500.0, 320.0, 240.0, -0.05]),
        2: ("OPENCV", [510.0, 505.0, 321.0, 238.0, -0.1, 0.02, 0.001, -0.001]),
        3: ("PINHOLE", [480.0, 482.0, 318.0, 242.0]),
        4: ("OPENCV_FISHEYE", [300.0, 301.0, 320.0, 240.0, 0.05, -0.01, 0.002, 0.0])}


def write_model(d, seed=0):
    rng = np.random.default_rng(seed)
    d.mkdir()
    X = rng.uniform(-1, 1, (300, 3)) + [0, 0, 5]
    with open(d / "cameras.txt", "w") as f:
        for cid, (m, p) in CAMS.items():
            f.write(f"{cid} {m} 640 480 " + " ".join(f"{v:.17g}" for v in p) + "\n")
    tracks = {j: [] for j in range(len(X))}
    lines = []
    for iid in range(1, 9):
        R = Rotation.from_rotvec(rng.normal(0, 0.1, 3)).as_matrix()
        t = rng.normal(0, 0.3, 3)
        cid = (iid - 1) % 4 + 1
        cam = pycolmap.Camera(model=CAMS[cid][0], width=640, height=480, params=CAMS[cid][1])
        uv = np.array([cam.img_from_cam(x) for x in X @ R.T + t]) + rng.normal(0, 0.7, (len(X), 2))
        pts = []
        for j in np.flatnonzero(rng.random(len(X)) < 0.7):
            tracks[j].append((iid, len(pts)))
            pts.append((uv[j, 0], uv[j, 1], j + 1))
        pts.append((100.5, 200.5, -1))  # a keypoint without a 3D point
        q = Rotation.from_matrix(R).as_quat()
        lines.append(f"{iid} {q[3]:.17g} {q[0]:.17g} {q[1]:.17g} {q[2]:.17g} {t[0]:.17g} {t[1]:.17g} {t[2]:.17g} "
                     f"{cid} img{iid}.png")
        lines.append(" ".join(f"{x:.17g} {y:.17g} {p}" for x, y, p in pts))
    (d / "images.txt").write_text("\n".join(lines) + "\n")
    with open(d / "points3D.txt", "w") as f:
        for j in range(len(X)):
            if len(tracks[j]) >= 2:
                f.write(f"{j + 1} {X[j, 0]:.17g} {X[j, 1]:.17g} {X[j, 2]:.17g} 128 128 128 0.5 "
                        + " ".join(f"{a} {b}" for a, b in tracks[j]) + "\n")


@pytest.mark.parametrize("kind", ["text", "binary"])
def test_reprojection_error_and_track_length_equal_pycolmap(tmp_path, kind, agreement):
    write_model(tmp_path / "text")
    rec = pycolmap.Reconstruction(str(tmp_path / "text"))
    if kind == "binary":
        (tmp_path / "binary").mkdir()
        rec.write_binary(str(tmp_path / "binary"))
    rec.update_point_3d_errors()
    ours = colmap_model_stats(tmp_path / kind)
    ref = (rec.compute_mean_reprojection_error(), rec.compute_mean_track_length(),
           rec.compute_mean_observations_per_reg_image())
    d = max(abs(ours.mean_reprojection_error_px - ref[0]), abs(ours.mean_track_length - ref[1]),
            abs(ours.mean_observations_per_image - ref[2]))
    assert d < 1e-9 and ours.n_points == rec.num_points3D() and ours.n_observations == rec.compute_num_observations()
    agreement(f"colmap.reprojection.{kind}", "mean reprojection error (px), mean track length, observations per "
              "image", "pycolmap `compute_mean_reprojection_error` etc.", pycolmap.__version__,
              f"8 images, 4 camera models, {kind} model", d)
