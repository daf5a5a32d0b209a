"""Gray-code and phase-shift decoders and triangulation on the analytic plane + sphere scene
(conftest.py): every camera pixel's projector coordinate in closed form, the patterns sampled
there, with and without noise."""
import numpy as np
import pytest

from recon_eval.estimators.structured_light.graycode import contrast_mask, decode_axis
from recon_eval.estimators.structured_light.phase import decode_phase
from recon_eval.estimators.structured_light.triangulate import column_quantisation_bound, ray_column, ray_ray
from recon_eval.metrics.structured_light import code_errors, depth_errors
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.sl_codes import pixel_index
from scenegen.imaging.patterns import gray_code, perfect_code, phase_shift


def _gray_decode(procam, images, seq, threshold, min_contrast):
    mask = contrast_mask(images[0], images[1], min_contrast)
    out = []
    for axis, length in (("u", seq.width), ("v", seq.height)):
        pat = [i for i, f in enumerate(seq.frames) if f.axis == axis and not f.inverse]
        inv = [i for i, f in enumerate(seq.frames) if f.axis == axis and f.inverse]
        out.append(decode_axis(images[pat], images[inv], length_px=length, threshold=threshold, mask=mask))
    dec = np.stack([np.where(a.code >= 0, a.code, np.nan) for a in out], axis=2).astype(np.float64)
    return dec


@pytest.fixture(scope="module")
def gray(procam):
    return gray_code(procam.projector.width, procam.projector.height)


@pytest.mark.parametrize("noise_sigma", [0.0, 0.03])
def test_gray_decoder_reads_the_truth_codes(procam, gray, noise_sigma):
    images = procam.observe(gray, noise_sigma=noise_sigma, seed=1)
    dec = _gray_decode(procam, images, gray, threshold=0.05, min_contrast=0.1)
    truth = perfect_code(gray, procam.uv)
    r = code_errors(dec, truth, procam.lit, lengths_px=(gray.width, gray.height))
    assert r.n_lit > 8000 and 0.9 * procam.lit.size > r.n_lit  # the sphere's shadow and the border are dark
    assert r.agreement >= 0.999 and r.completeness >= 0.999 and r.false_decode_frac == 0.0
    if noise_sigma == 0.0:
        assert r.agreement == 1.0 and r.max_px == 0.0


def test_the_threshold_rejects_what_noise_would_corrupt(procam, gray):
    images = procam.observe(gray, noise_sigma=0.12, seed=2)
    truth = perfect_code(gray, procam.uv)
    args = dict(lengths_px=(gray.width, gray.height))
    loose = code_errors(_gray_decode(procam, images, gray, 0.0, 0.1), truth, procam.lit, **args)
    strict = code_errors(_gray_decode(procam, images, gray, 0.15, 0.1), truth, procam.lit, **args)
    wrong = lambda r: 1.0 - r.agreement / r.completeness  # wrong codes among decoded lit pixels
    assert wrong(loose) > 0.01 and wrong(strict) < 0.2 * wrong(loose) and strict.completeness < loose.completeness


def test_ray_column_and_ray_ray_are_exact_for_exact_codes(procam):
    lit = procam.lit
    px = pixel_centers(procam.camera.width, procam.camera.height)[lit]
    args = (procam.camera, procam.cam_from_world, procam.projector, procam.proj_from_world, px)
    p_col = ray_column(*args, procam.uv[lit][:, 0])
    p_ray = ray_ray(*args, procam.uv[lit])
    assert np.max(np.linalg.norm(p_col - procam.points[lit], axis=1)) < 1e-9  # distorted projector: Newton
    assert np.max(np.linalg.norm(p_ray - procam.points[lit], axis=1)) < 1e-9


def test_gray_reconstruction_is_within_the_quantisation_bound(procam, gray):
    images = procam.observe(gray)
    dec = _gray_decode(procam, images, gray, threshold=0.05, min_contrast=0.1)
    ok = np.isfinite(dec[..., 0])
    px = pixel_centers(procam.camera.width, procam.camera.height)[ok]
    args = (procam.camera, procam.cam_from_world, procam.projector, procam.proj_from_world, px)
    pts = ray_column(*args, dec[ok][:, 0])
    bound = column_quantisation_bound(*args, dec[ok][:, 0])
    err = np.linalg.norm(pts - procam.points[ok], axis=1)
    assert np.all(err <= bound + 1e-12) and np.max(err) > 0.5 * np.max(bound)  # tight, not vacuous
    # the textbook size of half a column, 0.5 z^2 / (f_p b): 7.2 mm at z = 0.55 m, b = 0.15 m,
    # f_p = 140 px (the toe-in and the oblique plane change it by a factor below 2)
    assert 0.5 < np.median(bound) / (0.5 * 0.55 ** 2 / (140.0 * 0.15)) < 2.0
    depth = np.full(ok.shape, np.nan)
    depth[ok] = pts[:, 2]
    bmap = np.full(ok.shape, np.nan)
    bmap[ok] = bound
    d = depth_errors(depth, procam.points[..., 2], procam.lit, bound_m=bmap)
    assert d.within_bound_frac == 1.0 and d.completeness == 1.0 and d.max_abs_m <= np.max(bound)


def _phase_decode(procam, seq, images, min_modulation):
    periods = sorted({f.period_px for f in seq.frames}, reverse=True)
    n = seq.frames[0].n_steps
    frames = images.reshape(len(periods), n, *images.shape[1:])
    shifts = [f.shift_rad for f in seq.frames[:n]]
    return decode_phase(frames, periods_px=periods, shifts_rad=shifts, length_px=seq.width,
                        min_modulation=min_modulation)


def test_phase_decoder_reads_the_lit_pixel_and_its_noise_follows_the_formula(procam):
    seq = phase_shift(procam.projector.width, procam.projector.height, n_steps=4, periods_px=(128.0, 16.0))
    u = procam.uv[..., 0]
    lit = procam.lit
    clean = _phase_decode(procam, seq, procam.observe(seq, ambient=0.05), 0.05)
    # the projector shows a piecewise-constant image: a perfect decoder reads the centre of the
    # projector pixel that lights the point, so the error against the continuous u is that
    # pixel's quantisation, uniform in [-0.5, 0.5): RMS 1/sqrt(12) = 0.289 px
    assert np.all(clean.valid[lit])
    # float32 pattern values (2^-24) move the phase by ~1e-7 rad, p / (2 pi) 1e-7 ~ 2e-6 px
    np.testing.assert_allclose(clean.coord_px[lit], pixel_index(u[lit], seq.width), atol=1e-5)
    q_err = clean.coord_px[lit] - u[lit]
    assert np.max(np.abs(q_err)) <= 0.5 and abs(np.sqrt(np.mean(q_err ** 2)) - 12 ** -0.5) < 0.02
    # with Gaussian noise sigma the N-step phase has std sigma_phi = sqrt(2 / N) sigma / B
    # (B = albedo / 2), the coordinate std p sigma_phi / (2 pi) of the finest period p
    sigma = 0.01
    noisy = _phase_decode(procam, seq, procam.observe(seq, noise_sigma=sigma, seed=3), 0.05)
    ok = lit & noisy.valid  # noise pushes a few pixels of the projector's edge column outside it
    e = noisy.coord_px[ok] - clean.coord_px[ok]
    predicted = 16.0 / (2 * np.pi) * np.sqrt(2 / 4) * sigma / (procam.albedo[ok] / 2)
    assert np.mean(noisy.valid[lit]) > 0.995
    ratio = np.sqrt(np.mean(e ** 2)) / np.sqrt(np.mean(predicted ** 2))
    assert 0.9 < ratio < 1.1
    truth = perfect_code(seq, procam.uv)[..., :1]
    r = code_errors(noisy.coord_px[..., None], truth, lit, lengths_px=(seq.width,), truth_px=procam.uv[..., :1])
    assert r.completeness > 0.995 and r.against == "coordinates"
