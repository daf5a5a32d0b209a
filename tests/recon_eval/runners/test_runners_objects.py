"""The object recognition runners on a synthetic BOP dataset (bop_scene.py): each writes a BOP19
CSV that `recon-eval objects` reads, and recovers the poses of the synthetic scene."""
from __future__ import annotations

import pytest

import bop_scene
from recon_eval.runners import objects_align, objects_features


@pytest.fixture(scope="module")
def bop(tmp_path_factory):
    return bop_scene.write(tmp_path_factory.mktemp("bop"))


def test_alignment_fpfh_ransac_icp(bop, tmp_path):
    # fewer trials and RANSAC iterations than the method's defaults (4 x 5000: AR 0.48 here), for time
    out = objects_align.run(bop, tmp_path, {"trials": 2, "ransac_iterations": 3000})
    r = out.results["bop19"]
    assert (tmp_path / "poses_bop19.csv").is_file() and out.raw_files == ["poses_bop19.csv"]
    assert r.n_targets == 5 and r.ar > 0.1  # at least one instance found (random poses score 0)


def test_sift_pnp_ransac(bop, tmp_path):
    out = objects_features.run(bop, tmp_path, {})
    r = out.results["bop19"]
    assert out.notes["reference_views"] == 32 and r.n_targets == 5
    assert r.ar_mssd >= 0.9 and r.ar >= 0.9, out.metrics  # textured, noise-free: AR 0.97 measured
