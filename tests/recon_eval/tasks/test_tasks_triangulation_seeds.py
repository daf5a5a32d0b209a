"""The triangulation task's per-pair seeds come from scenegen.geometry.seeds and are the ones it
used before the restructure (``SeedSequence([seed, crc32(pair), 0 | 1])``): the same datasets give
byte-identical task files."""
import zlib

import numpy as np

from recon_eval.tasks.triangulation_task import build_pair, pair_name
from recon_eval.readers.scenegen_dataset import read_dataset
from scenegen.geometry import seeds


def _old_parts(seed, name, k):
    return [int(seed), zlib.crc32(name.encode("utf-8")), k]


def test_seeds_match_the_former_derivation():
    for seed, name in [(0, "a__b"), (7, "ref_0000__tilt_0003"), (2**31, "pair_0000__pair_0001")]:
        old = np.random.default_rng(_old_parts(seed, name, 0)).permutation(1000)
        np.testing.assert_array_equal(seeds.rng(seed, name, 0).permutation(1000), old)
        assert seeds.seed32(seed, name, 1) == int(np.random.SeedSequence(_old_parts(seed, name, 1)).generate_state(1)[0])


def test_pair_selection_and_noise_use_them(plane_dataset):
    ds = read_dataset(plane_dataset[0])
    a = build_pair(ds, "left_000", "free_000", 1.0, count=50, seed=3)
    b = build_pair(ds, "left_000", "free_000", 1.0, count=50, seed=3)
    np.testing.assert_array_equal(a.observations, b.observations)
    clean = build_pair(ds, "left_000", "free_000", 0.0, count=50, seed=3)
    np.testing.assert_array_equal(clean.points_true, a.points_true)  # the points do not depend on sigma
    noise = np.random.default_rng(seeds.seed32(3, pair_name("left_000", "free_000"), 1)).normal(
        scale=1.0, size=(len(a.points_true) * 2, 2)).reshape(-1, 4)
    np.testing.assert_allclose(a.observations - clean.observations, noise, atol=1e-9)
