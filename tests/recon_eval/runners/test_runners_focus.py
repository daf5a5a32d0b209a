"""Depth from focus (recon_eval.runners.focus) and the circle-of-confusion truth it is built on."""
from pathlib import Path

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from recon_eval.runners import run_method
from recon_eval.runners.focus import depth_from_focus
from scenegen.dataset import Dataset
from scenegen.pipeline.run import render_spec

SCENE = Path(__file__).parents[3] / "scenes" / "focus_stack.yaml"


def test_sml_finds_the_focus_of_two_depths_on_a_synthetic_stack():
    rng = np.random.default_rng(0)
    tex = rng.uniform(size=(40, 60))
    depth = np.where(np.arange(60)[None, :] < 30, 0.5, 0.8) * np.ones((40, 1))
    focus = 1.0 / np.linspace(2.4, 1.0, 10)
    # blur grows linearly with |1/Z_f - 1/Z| (thin lens); a Gaussian stands in for the disc
    stack = []
    for zf in focus:
        out = np.empty_like(tex)
        for z in (0.5, 0.8):
            sigma = 3.0 * abs(1 / zf - 1 / z)
            out[depth == z] = (gaussian_filter(tex, sigma) if sigma > 0 else tex)[depth == z]
        stack.append(out)
    est, _ = depth_from_focus(np.stack(stack), focus, window=3)
    inner = np.abs(np.arange(60) - 30)[None, :] > 5
    step = np.diff(1 / focus).__abs__().max()
    assert np.abs(1 / est - 1 / depth)[:, inner[0]].max() <= step  # within one step of the sweep


@pytest.fixture(scope="module")
def stack(tmp_path_factory):
    out = tmp_path_factory.mktemp("focus") / "focus"
    render_spec(SCENE, out, spp=16, progress=False, show_warnings=False)
    return out


@pytest.mark.render
def test_coc_truth_is_the_thin_lens_formula_of_the_recorded_lens(stack):
    d = Dataset(stack)
    for v in d.views[::4]:
        lens = d.view_info(v)["optics"]["lens"]
        cam, _ = d.camera(v)
        t = d.truth(v)
        A = cam.fx * lens["pixel_pitch_um"] * 1e-6 / (2 * lens["f_number"])
        want = cam.fx * A * np.abs(1 / lens["focus_distance_m"] - 1 / t["depth_z"].astype(np.float64))
        coc = d.coc_radius_px(v)
        np.testing.assert_allclose(coc[t["valid"]], want[t["valid"]], rtol=1e-6)
        assert np.isnan(coc[~t["valid"]]).all()


@pytest.mark.render
def test_sml_depth_from_focus_on_the_rendered_stack(stack, tmp_path):
    # at 16 spp (the scene's own 64 spp: all 0.041, slanted 0.015, ball 0.015; here measured
    # all 0.069, slanted 0.034, ball 0.041: the focus measure sees the Monte Carlo noise)
    m = run_method("sml-dff", stack, tmp_path / "run")["metrics"]
    assert m["all.none.abs_rel"] < 0.08 and m["all.none.a1"] > 0.9
    assert m["slanted.none.abs_rel"] < 0.06 and m["ball.none.abs_rel"] < 0.06


def test_stm_recovers_depth_from_two_gaussian_blurs():
    # per-axis sigma^2 = R^2 / 4 (a disc's second moment), R = K |1/Z_f - 1/Z|
    rng = np.random.default_rng(2)
    tex = gaussian_filter(rng.uniform(size=(60, 80)), 1.0)
    K, f1, f2 = 2.0, 0.45, 1.0
    depth = np.where(np.arange(80)[None, :] < 40, 0.6, 0.8) * np.ones((60, 1))
    imgs = []
    for zf in (f1, f2):
        out = np.empty_like(tex)
        for z in (0.6, 0.8):
            out[depth == z] = gaussian_filter(tex, K * abs(1 / zf - 1 / z) / 2)[depth == z]
        imgs.append(out)
    from recon_eval.runners.focus import depth_from_defocus
    est = depth_from_defocus(imgs[0], imgs[1], f1, f2, K, 4.0)
    inner = np.abs(np.arange(80) - 40)[None, :] > 12
    inner = inner & (np.abs(np.arange(60) - 30)[:, None] < 20)
    assert np.nanmedian(np.abs(est - depth)[inner] / depth[inner]) < 0.03  # measured 0.011


@pytest.mark.render
def test_stm_depth_from_defocus_on_the_rendered_pair(tmp_path):
    out = tmp_path / "pair"
    render_spec(SCENE.parent / "defocus_pair.yaml", out, progress=False, show_warnings=False)
    m = run_method("stm-dfd", out, tmp_path / "run")["metrics"]
    # measured (64 spp): abs_rel 0.076 over all (wall 0.128, slanted 0.038, ball 0.033), coverage 1
    assert m["all.none.abs_rel"] < 0.1 and m["slanted.none.abs_rel"] < 0.05 and m["ball.none.abs_rel"] < 0.05
    assert m["coverage"] == 1.0
