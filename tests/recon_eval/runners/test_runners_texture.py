"""Shape from texture (recon_eval.runners.texture) and the plane orientation metric."""
from pathlib import Path

import cv2
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from recon_eval.metrics.normals import plane_orientation_metrics, slant_tilt_deg
from recon_eval.runners import run_method
from recon_eval.runners.texture import plane_normal_from_texture
from scenegen.pipeline.run import render_spec

SCENE = Path(__file__).parents[3] / "scenes" / "shape_from_texture.yaml"


def test_slant_tilt_of_planted_normals():
    s, t = np.radians(40.0), np.radians(-120.0)
    n = np.array([np.sin(s) * np.cos(t), np.sin(s) * np.sin(t), -np.cos(s)])
    assert slant_tilt_deg(n) == pytest.approx((40.0, -120.0))
    assert slant_tilt_deg(-n) == pytest.approx((40.0, -120.0))  # either sign
    r = plane_orientation_metrics(n, n * [-1, -1, 1])  # the mirror: tilt off by 180 deg
    assert r.angle_err_deg == pytest.approx(80.0) and r.angle_err_folded_deg < 1e-6 and r.tilt_err_deg == pytest.approx(180.0)


@pytest.mark.parametrize("slant_deg, tilt_deg", [(30.0, 20.0), (50.0, -70.0), (60.0, 135.0)])
def test_foreshortened_isotropic_texture_gives_its_slant(slant_deg, tilt_deg):
    # an isotropic texture (smoothed white noise) compressed by cos(slant) along the tilt direction
    rng = np.random.default_rng(7)
    tex = gaussian_filter(rng.normal(size=(600, 600)), 2.5)
    t = np.radians(tilt_deg)
    R = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
    A = R @ np.diag([np.cos(np.radians(slant_deg)), 1.0]) @ R.T  # compress along t
    M = np.c_[A, np.array([100.0, 100.0]) - A @ np.array([300.0, 300.0])]
    img = cv2.warpAffine(tex, M, (200, 200), flags=cv2.INTER_CUBIC)
    n = plane_normal_from_texture(img, np.ones(img.shape, bool), 4.0)
    s_est, t_est = slant_tilt_deg(n)
    assert abs(s_est - slant_deg) < 3.0
    assert min(abs((t_est - tilt_deg + 180) % 360 - 180), abs((t_est - tilt_deg) % 360 - 180)) < 3.0  # up to the sign


@pytest.mark.render
def test_runner_on_the_rendered_plane(tmp_path):
    out = tmp_path / "tex"
    render_spec(SCENE, out, progress=False, show_warnings=False)
    m = run_method("texture-structure-tensor", out, tmp_path / "run")["metrics"]
    # measured: slant errors 5.2, 3.4, 2.2, 9.9, 10.0, 8.2 deg; folded angle errors 3.8 .. 11.4 deg
    assert m["mean_slant_err_deg"] < 8.0 and m["mean_angle_err_folded_deg"] < 10.0
