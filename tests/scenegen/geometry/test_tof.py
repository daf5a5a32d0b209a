"""AMCW decoding (scenegen.geometry.tof) against closed forms: the four-tap correlation of a
phasor decodes to its phase, amplitude and offset; ranges wrap at exactly c / (2 f); two
frequencies unwrap to the range (checked against a brute-force search over every wrap-count pair)."""
from __future__ import annotations

import math

import numpy as np

from scenegen.geometry import tof as g


def test_four_taps_decode_to_the_phase_amplitude_and_offset():
    rng = np.random.default_rng(0)
    phi = rng.uniform(0, 2 * math.pi, 1000)
    A, B = rng.uniform(1, 100, 1000), rng.uniform(200, 300, 1000)
    # a path sum with phasor (A / k) e^{i phi} and DC B / k, k = 3 electrons per unit
    frames = g.raw_frames(B / 3.0, A / 3.0 * np.cos(phi), A / 3.0 * np.sin(phi), electrons_per_unit=3.0)
    # C(psi) = B + A cos(phi - psi), written out independently
    np.testing.assert_allclose(frames, B[:, None] + A[:, None] * np.cos(phi[:, None] - np.arange(4) * math.pi / 2),
                               rtol=1e-13, atol=1e-10)
    p, a, b = g.decode_phase(frames)
    np.testing.assert_allclose(np.angle(np.exp(1j * (p - phi))), 0, atol=1e-12)
    np.testing.assert_allclose(a, A, rtol=1e-12)
    np.testing.assert_allclose(b, B, rtol=1e-12)


def test_a_direct_path_decodes_to_its_range_and_wraps_at_c_over_2f():
    f = 80e6
    R = g.ambiguity_range_m(f)
    assert R == 299_792_458.0 / 160e6
    r = np.array([0.0, 0.3, R * (1 - 1e-9), R, R * (1 + 1e-9), 2.5 * R, 3 * R - 0.01])
    phase = np.mod(g.phase_of_path_rad(2 * r, f), 2 * math.pi)
    frames = g.raw_frames(np.ones_like(r), np.cos(phase), np.sin(phase), electrons_per_unit=1000.0)
    decoded = g.range_from_phase_m(g.decode_phase(frames)[0], f)
    np.testing.assert_allclose(decoded, r - np.floor(r / R) * R, atol=1e-9)
    assert decoded[3] < 1e-9 and decoded[2] > R - 1e-6  # the wrap is at R, not before, not after
    assert g.wrap_count(r, f).tolist() == [0, 0, 0, 1, 1, 2, 2]
    assert g.wrap_count(np.array([np.inf, np.nan]), f).tolist() == [-1, -1]


def _brute_unwrap(r1, r2, f1, f2, top):
    R1, R2 = g.ambiguity_range_m(f1), g.ambiguity_range_m(f2)
    best = (np.inf, None)
    for n1 in range(int(top / R1) + 2):
        for n2 in range(int(top / R2) + 2):
            a, b = r1 + n1 * R1, r2 + n2 * R2
            if a < top and abs(a - b) < best[0]:
                best = (abs(a - b), (n1, n2))
    return best[1]


def test_two_frequencies_unwrap_to_the_range_within_the_pair_s_unambiguous_range():
    f1, f2 = 100e6, 80e6
    top = g.unambiguous_range_two_m(f1, f2)
    assert math.isclose(top, 299_792_458.0 / 40e6)
    rng = np.random.default_rng(1)
    r = rng.uniform(0.05, top - 0.05, 400)  # 5 sigma from either end of the unambiguous range
    noise = rng.normal(0, 0.01, (2, 400))  # 1 cm of range noise on each wrapped reading
    r1 = np.mod(r + noise[0], g.ambiguity_range_m(f1))
    r2 = np.mod(r + noise[1], g.ambiguity_range_m(f2))
    out, n1, n2 = g.unwrap_two(r1, r2, f1, f2)
    for i in range(0, 400, 10):
        assert (n1[i], n2[i]) == _brute_unwrap(r1[i], r2[i], f1, f2, top)
    np.testing.assert_array_less(np.abs(out - r), 0.05)
    exact, _, _ = g.unwrap_two(np.mod(r, g.ambiguity_range_m(f1)), np.mod(r, g.ambiguity_range_m(f2)), f1, f2)
    np.testing.assert_allclose(exact, r, atol=1e-9)
    assert np.isnan(g.unwrap_two(np.array([np.nan]), np.array([1.0]), f1, f2)[0][0])
