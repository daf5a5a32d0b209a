"""Depth from zooming (recon_eval.runners.zoom): exact on exact projections, and on the rendered
zoom series."""
from pathlib import Path

import numpy as np
import pytest

from recon_eval.runners import run_method
from recon_eval.runners.zoom import depth_from_zoom
from scenegen.pipeline.run import render_spec

SCENE = Path(__file__).parents[3] / "scenes" / "zoom_series.yaml"


def test_radial_magnification_gives_the_depth_of_exact_projections():
    rng = np.random.default_rng(4)
    P = np.c_[rng.uniform(-0.5, 0.5, (200, 2)), rng.uniform(0.6, 1.5, 200)]  # first camera's frame
    c = np.array([79.5, 59.5])
    f1, f2, d = 120.0, 172.8, 0.08  # the second camera 0.08 m further along the axis
    x1 = c + f1 * P[:, :2] / P[:, 2:]
    x2 = c + f2 * P[:, :2] / (P[:, 2:] - d)
    z = depth_from_zoom(x1, x2, c, c, f1, f2, d, min_radius_px=15.0)
    ok = np.isfinite(z)
    assert ok.sum() > 100
    np.testing.assert_allclose(z[ok], P[ok, 2], rtol=1e-9)
    assert not ok[np.linalg.norm(x1 - c, axis=1) <= 15.0].any()


@pytest.mark.render
def test_runner_on_the_rendered_zoom_series(tmp_path):
    out = tmp_path / "zoom"
    render_spec(SCENE, out, progress=False, show_warnings=False)
    m = run_method("sift-zoom-depth", out, tmp_path / "run")["metrics"]
    # measured: 109 points, abs_rel 0.086, a1 0.93 (SIFT's localisation against a radial shift of a
    # few px per 0.04 m of pupil travel)
    assert m["n_points"] > 50 and m["abs_rel"] < 0.12 and m["a1"] > 0.85
