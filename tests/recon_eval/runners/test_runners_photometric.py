"""Woodham's photometric stereo and Frankot-Chellappa integration (recon_eval.runners.photometric).

The bound of the rendered test, per pixel of the Lambertian sphere: Woodham solves b = L+ I over
the lights that reach the pixel, so an error dI in the observations moves b by at most
||L+||_2 ||dI||_2 and the normal by at most asin(||L+||_2 ||dI||_2 / rho). dI_k bounds the two
errors of the input: the 8-bit sRGB quantisation (half a code value, in linear units at the
pixel's value) and the render's Monte Carlo noise and box-filter bias around the pixel-centre
model (tests/scenegen/render/test_photometric_truth.py: 5 standard deviations of the pixel mean at
16 spp plus the curvature bias), divided by the light's intensity and averaged over the channels as
the method does. Pixels: the sphere's interior (3x3), where every light is clearly lit
(n . l > 0.05) or clearly not (n . l < 0) in the 3x3 neighbourhood, so the method's shadow test
(0.02) keeps exactly the lights that reach it. Measured: at most 0.26 deg against a bound of
2.7 deg (median), 0.10 of it at worst, on 570 pixels.
"""
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from recon_eval.cli import main as cli_main
from recon_eval.readers.photometric import photometric_sets
from recon_eval.runners import run_method
from recon_eval.runners.photometric import frankot_chellappa, woodham
from scenegen.dataset import Dataset
from scenegen.geometry.color import linear_from_srgb
from scenegen.pipeline.run import render_spec

SCENE = Path(__file__).parents[3] / "scenes" / "photometric_stereo.yaml"
SPP = 16


def test_frankot_chellappa_recovers_a_bump():
    # a Gaussian bump whose gradient vanishes at the borders (FC's periodic model holds there)
    v, u = np.mgrid[0:48, 0:64].astype(np.float64)
    g = np.exp(-((u - 31.5) ** 2 + (v - 23.5) ** 2) / (2 * 7.0 ** 2))
    h = 5.0 * g
    p, q = -h * (u - 31.5) / 7.0 ** 2, -h * (v - 23.5) / 7.0 ** 2  # dh/du, dh/dv
    rec = frankot_chellappa(p, q)
    err = (rec - h) - np.mean(rec - h)
    assert np.abs(err).max() < 0.01 * h.max()
    assert np.abs(frankot_chellappa(-p, -q) + h - np.mean(frankot_chellappa(-p, -q) + h)).max() < 0.01 * h.max()


def test_woodham_is_exact_on_exact_lambertian_data():
    rng = np.random.default_rng(1)
    n = rng.normal(size=(6, 7, 3))
    n[..., 2] = -np.abs(n[..., 2]) - 1.0  # facing the camera (OpenCV: -z)
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    L = np.array([[0.3, 0.1, -1], [-0.2, 0.3, -1], [0.1, -0.4, -1], [-0.3, -0.2, -1], [0.0, 0.0, -1]])
    L /= np.linalg.norm(L, axis=1, keepdims=True)
    e = np.array([[1.0, 0.9, 0.8]] * 5)
    rho = rng.uniform(0.3, 0.9, size=(6, 7, 3))
    imgs = rho[None] * np.clip(np.einsum("hwc,kc->khw", n, L), 0, None)[..., None] * e[:, None, None, :]
    n_est, a_est = woodham(imgs, L, e, np.ones((6, 7), bool), 0.0)
    np.testing.assert_allclose(n_est, n, atol=1e-12)
    np.testing.assert_allclose(a_est, rho, atol=1e-12)


def test_woodham_with_more_lights_than_bits_in_an_integer():
    # DiLiGenT has 96 lights: the shadow subsets must not be packed into a 64-bit code
    rng = np.random.default_rng(5)
    K = 96
    L = np.c_[rng.uniform(-0.5, 0.5, (K, 2)), -np.ones(K)]
    L /= np.linalg.norm(L, axis=1, keepdims=True)
    n = np.c_[rng.uniform(-0.7, 0.7, (30, 2)), -np.ones(30)]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n = n.reshape(5, 6, 3)
    imgs = 0.6 * np.clip(np.einsum("hwc,kc->khw", n, L), 0, None)[..., None] * np.ones(3)
    n_est, a_est = woodham(imgs, L, np.ones((K, 3)), np.ones((5, 6), bool), 0.01)
    np.testing.assert_allclose(n_est, n, atol=1e-12)
    np.testing.assert_allclose(a_est, 0.6, atol=1e-12)


@pytest.fixture(scope="module")
def ps_dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("ps") / "ps"
    render_spec(SCENE, out, spp=SPP, progress=False, show_warnings=False)
    return out


def _bound_deg(s, d, on, ndl):
    """Per-pixel bound (module docstring) and the pixels it holds for."""
    keep = ndimage.binary_erosion(on, np.ones((3, 3)), border_value=0)
    for k in range(len(s.views)):
        lit = ndimage.minimum_filter(np.where(on, ndl[k], -1.0), 3) > 0.05
        dark = ndimage.maximum_filter(np.where(on, ndl[k], 1.0), 3) < 0
        keep &= lit | dark
    dI = []
    for k, v in enumerate(s.views):
        c = d.image(v).astype(np.float64)
        q = np.maximum(linear_from_srgb(np.minimum(c + 0.5, 255) / 255) - linear_from_srgb(c / 255),
                       linear_from_srgb(c / 255) - linear_from_srgb(np.maximum(c - 0.5, 0) / 255))
        p = np.where(on[..., None], s.albedo * np.clip(ndl[k], 0, None)[..., None] * s.intensities[k], 0.0)
        fu, fv = (np.roll(p, -1, 1) - np.roll(p, 1, 1)) / 2, (np.roll(p, -1, 0) - np.roll(p, 1, 0)) / 2
        fuu = np.roll(p, -1, 1) - 2 * p + np.roll(p, 1, 1)
        fvv = np.roll(p, -1, 0) - 2 * p + np.roll(p, 1, 0)
        mc = 5 * np.sqrt((fu ** 2 + fv ** 2) / 12 / SPP) + np.abs(fuu + fvv) / 24 + 1e-5
        dI.append(((q + mc) / s.intensities[k]).mean(axis=-1))
    dI = np.stack(dI)
    bound = np.full(on.shape, np.nan)
    for y, x in zip(*np.nonzero(keep)):
        use = ndl[:, y, x] > 0
        pinv_norm = 1.0 / np.linalg.svd(s.directions_cam[use], compute_uv=False).min()
        bound[y, x] = np.degrees(np.arcsin(min(1.0, pinv_norm * np.linalg.norm(dI[use, y, x]) / s.albedo[y, x].mean())))
    return bound, keep


@pytest.mark.render
def test_woodham_recovers_the_lambertian_sphere_within_the_derived_bound(ps_dataset):
    (s,) = photometric_sets(ps_dataset)
    on = s.object_id == s.objects["lambertian"]
    n_est, _ = woodham(s.images_linear, s.directions_cam, s.intensities, s.object_id > 0, 0.02)
    err = np.degrees(np.arccos(np.clip(np.sum(s.normals_cam * n_est, axis=-1), -1, 1)))
    ndl = np.einsum("hwc,kc->khw", np.nan_to_num(s.normals_cam), s.directions_cam)
    bound, keep = _bound_deg(s, Dataset(ps_dataset), on, ndl)
    assert keep.sum() > 400
    assert (err[keep] <= bound[keep]).all()
    assert np.median(bound[keep]) < 5.0  # the bound says something


@pytest.mark.render
def test_runner_error_grows_with_specular_and_shadowed_cases(ps_dataset, tmp_path):
    doc = run_method("woodham-ps", ps_dataset, tmp_path / "run")
    m = doc["metrics"]
    assert m["lambertian.mean_ae_deg"] < 0.5
    assert m["lambertian.mean_ae_deg"] < m["shadowed.mean_ae_deg"] < m["specular.mean_ae_deg"]
    assert m["lambertian.albedo_rel_mae"] < 0.05
    assert (tmp_path / "run" / "ps" / "normals.npy").is_file() and (tmp_path / "run" / "result.json").is_file()
    gates = Path(__file__).parents[3] / "gates" / "photometric_stereo.yaml"
    assert cli_main(["gate", str(gates), str(tmp_path / "run" / "result.json"), "-q"]) == 0  # the project's gates hold


@pytest.mark.render
def test_near_light_runner_beats_the_plane_and_distant_approximations(tmp_path):
    out = tmp_path / "near"
    render_spec(SCENE.parent / "photometric_stereo_near.yaml", out, progress=False, show_warnings=False)
    m = run_method("woodham-near-ps", out, tmp_path / "run")["metrics"]
    # measured: 0.164 deg after 4 rounds, 1.03 deg with every pixel on the start plane, 14.3 deg
    # with distant lights taken at the object's centre
    assert m["lambertian.mean_ae_deg"] < 0.3 < 0.5 < m["plane.mean_ae_deg"] < 5.0 < m["distant.mean_ae_deg"]


@pytest.mark.render
def test_external_normals_kind_and_recon_eval_normals_agree(ps_dataset, tmp_path):
    """A user's method given the set's images, lights and mask: the truth normals score 0 deg under
    woodham-ps's names; ``recon-eval normals --json`` on the same file gives the same headline."""
    import json
    from pathlib import Path

    from recon_eval.cli import main
    from recon_eval.runners.declared import external_method

    est = Path(__file__).resolve().parent / "estimators" / "true_normals.py"
    m = external_method("my-ps", "normals", f"{{python}} {est} {{dataset}} {{out}} {{images}}")
    doc = run_method("my-ps", ps_dataset, tmp_path / "mine", declared={"my-ps": m})
    ref = run_method("woodham-ps", ps_dataset, tmp_path / "ref")
    names = {k for k in ref["metrics"] if k.endswith(("_ae_deg", "within_10deg"))}
    assert set(doc["metrics"]) == names and doc["inputs"]["task"] == ref["inputs"]["task"]
    # float32 truth: |n|^2 = 1 +- ~2.4e-7, and DiLiGenT's acos(dot) without normalising turns that into up to
    # sqrt(2 * 2.4e-7) rad = 0.04 deg a pixel
    assert doc["metrics"]["all.mean_ae_deg"] < 0.04 and doc["metrics"]["all.within_10deg"] == 1.0
    out = tmp_path / "n.json"
    assert main(["normals", str(tmp_path / "mine" / "ps" / "normals.npy"), str(ps_dataset), "--json", str(out),
                 "-q"]) == 0
    assert json.loads(out.read_text())["metrics"] == pytest.approx(doc["metrics"], abs=1e-12)
