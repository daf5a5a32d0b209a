"""Pattern generators and the structured-light code rules, against independent constructions."""
import itertools

import numpy as np
import pytest

from scenegen.geometry import sl_codes
from scenegen.imaging import patterns as P


def _reflected_gray(n_bits):
    """Gray code words by the reflect-and-prefix construction (Gray's patent, 1953)."""
    words = ["0", "1"]
    for _ in range(n_bits - 1):
        words = ["0" + w for w in words] + ["1" + w for w in reversed(words)]
    return np.array([int(w, 2) for w in words])


def test_gray_code_matches_the_reflected_construction_and_inverts():
    for n in (1, 3, 6, 10):
        c = np.arange(2 ** n)
        np.testing.assert_array_equal(P.binary_to_gray(c), _reflected_gray(n))
        np.testing.assert_array_equal(P.gray_to_binary(P.binary_to_gray(c)), c)


def test_pixel_index_follows_the_centre_convention():
    u = np.array([-0.5, -0.0001, 0.0, 0.4999, 0.5, 9.4999, 9.5, -0.50001, np.nan])
    np.testing.assert_array_equal(sl_codes.pixel_index(u, 10), [0, 0, 0, 0, 1, 9, -1, -1, -1])


@pytest.mark.parametrize("gen", [P.gray_code, P.binary_code])
def test_bit_frames_decode_every_projector_pixel(gen):
    W, H = 37, 20  # not powers of two
    seq = gen(W, H)
    assert seq.images.shape == (2 + 2 * (6 + 5), H, W) and seq.images.dtype == np.float32
    assert [f.kind for f in seq.frames[:2]] == ["white", "black"] and seq.axes == ("u", "v")
    np.testing.assert_array_equal(seq.images[0], 1.0)
    for axis, length, ref in (("u", W, np.arange(W)[None, :]), ("v", H, np.arange(H)[:, None])):
        idx = [i for i, f in enumerate(seq.frames) if f.axis == axis and not f.inverse]
        inv = [i for i, f in enumerate(seq.frames) if f.axis == axis and f.inverse]
        assert [seq.frames[i].bit for i in idx] == list(range(sl_codes.bits_for(length)))
        bits = seq.images[idx] > seq.images[inv]  # pattern vs inverse
        word = sl_codes.code_from_bits(bits)
        code = P.gray_to_binary(word) if gen is P.gray_code else word
        np.testing.assert_array_equal(code, np.broadcast_to(ref, (H, W)))
    if gen is P.gray_code:  # neighbouring columns differ in exactly one frame
        cols = seq.images[[i for i, f in enumerate(seq.frames) if f.axis == "u" and not f.inverse]][:, 0, :]
        assert np.all(np.abs(np.diff(cols, axis=1)).sum(axis=0) == 1)


def test_phase_frames_give_the_phase_and_unwrap_to_the_pixel():
    W, H = 200, 10
    seq = P.phase_shift(W, H, n_steps=5, periods_px=(256, 32, 8))
    assert seq.images.shape == (15, H, W)
    c = np.arange(W, dtype=np.float64)
    wrapped = []
    for p in (256.0, 32.0, 8.0):
        idx = [i for i, f in enumerate(seq.frames) if f.period_px == p]
        phi, mod = sl_codes.wrapped_phase(seq.images[idx][:, 0, :], [seq.frames[i].shift_rad for i in idx])
        d = np.angle(np.exp(1j * (phi - 2 * np.pi * (c + 0.5) / p)))
        assert np.max(np.abs(d)) < 1e-6 and np.allclose(mod, 0.5, atol=1e-6)  # float32 images
        wrapped.append(phi)
    np.testing.assert_allclose(sl_codes.unwrap_temporal(wrapped, (256, 32, 8)), c, atol=1e-4)
    with pytest.raises(ValueError, match="coarsest period"):
        P.phase_shift(W, H, periods_px=(100, 10))
    assert P.default_periods_px(640) == (640.0, 80.0, 10.0)


def test_de_bruijn_windows_are_unique():
    np.testing.assert_array_equal(sl_codes.de_bruijn(2, 3), [0, 0, 0, 1, 0, 1, 1, 1])  # B(2, 3)
    for k, n in ((3, 3), (5, 3), (7, 2)):
        s = sl_codes.de_bruijn(k, n)
        wrap = np.concatenate([s, s[:n - 1]])
        windows = {tuple(wrap[i:i + n]) for i in range(s.size)}
        assert s.size == k ** n and len(windows) == k ** n


def test_debruijn_stripes_name_their_position():
    W, H, s = 300, 8, 3
    seq = P.debruijn_stripes(W, H, stripe_px=s, symbols=5)
    img = seq.images[0]
    assert img.shape == (H, W, 3) and seq.frames[0].order == 3
    stripes = img[0, ::s]  # (n_stripes, 3) colours
    assert np.all(np.any(stripes[1:] != stripes[:-1], axis=1))  # neighbours differ
    words = (stripes @ np.array([4, 2, 1])).astype(int)
    trans = words[1:] ^ words[:-1]  # transitions between stripes i-1 and i
    n = seq.frames[0].order
    windows = [tuple(trans[i:i + n]) for i in range(trans.size - n + 1)]
    assert len(set(windows)) == len(windows)  # each window of n transitions names its place


def test_random_dots_are_seeded():
    a = P.random_dots(64, 48, seed=3, density=0.2, dot_px=2)
    b = P.random_dots(64, 48, seed=3, density=0.2, dot_px=2)
    c = P.random_dots(64, 48, seed=4, density=0.2, dot_px=2)
    assert np.array_equal(a.images, b.images) and not np.array_equal(a.images, c.images)
    assert abs(a.images.mean() - 0.2) < 0.05 and np.all(a.images[0, ::2, ::2] == a.images[0, 1::2, 1::2])
    with pytest.raises(ValueError, match="no projector coordinate"):
        P.perfect_code(a, np.zeros((1, 2)))


def test_sample_and_perfect_code_at_continuous_coordinates():
    W, H = 37, 20
    seq = P.gray_code(W, H)
    rng = np.random.default_rng(0)
    uv = np.stack([rng.uniform(-3, W + 3, 500), rng.uniform(-3, H + 3, 500)], axis=1)
    code = P.perfect_code(seq, uv)
    inside = (uv[:, 0] >= -0.5) & (uv[:, 0] < W - 0.5) & (uv[:, 1] >= -0.5) & (uv[:, 1] < H - 0.5)
    np.testing.assert_array_equal(code[inside], np.floor(uv[inside] + 0.5).astype(int))
    assert np.all(code[~inside] == -1)
    vals = P.sample(seq, uv)
    assert vals.shape == (len(seq.frames), 500) and np.all(vals[:, ~inside] == 0)
    for i, (u, v) in itertools.islice(((i, tuple(code[i])) for i in np.flatnonzero(inside)), 20):
        np.testing.assert_array_equal(vals[:, i], seq.images[:, v, u])
    deb = P.debruijn_stripes(W, H, stripe_px=4)
    assert P.sample(deb, uv).shape == (1, 500, 3)
    np.testing.assert_array_equal(P.perfect_code(deb, uv)[inside, 0], code[inside, 0] // 4)
    assert np.all(P.perfect_code(deb, uv)[:, 1] == -1)
    with pytest.raises(ValueError, match="axes"):
        P.gray_code(W, H, axes=("x",))
