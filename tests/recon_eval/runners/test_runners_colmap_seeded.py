"""pycolmap-incremental is reproducible: every COLMAP stage gets one thread and every random
generator the runner's seed (without them the max rotation error on orbit_sfm varied by ~1e-3 deg
from run to run; the rendered check that two runs agree bit for bit is in
test_runners_scenes.py)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pycolmap  # a dev dependency (pyproject.toml): required, never skipped

from recon_eval.runners import colmap


def test_every_stage_is_single_threaded_and_seeded(tmp_path, monkeypatch):
    import cv2

    seen = {}
    monkeypatch.setattr(pycolmap, "set_random_seed", lambda s: seen.setdefault("global_seed", s))
    monkeypatch.setattr(pycolmap, "extract_features", lambda *a, **kw: seen.setdefault("extract", kw))
    monkeypatch.setattr(pycolmap, "match_exhaustive", lambda *a, **kw: seen.setdefault("match", kw))
    monkeypatch.setattr(pycolmap, "incremental_mapping", lambda *a, **kw: seen.setdefault("map", kw) and {})
    views = ("a", "b", "c")
    for v in views:
        cv2.imwrite(str(tmp_path / f"{v}.png"), np.zeros((8, 8), np.uint8))
    ds = SimpleNamespace(views=views, root=tmp_path, image_path=lambda v: tmp_path / f"{v}.png")
    out = colmap.incremental(ds, tmp_path / "out", {})
    assert out.notes["failed"] == "no reconstruction"  # the stubs map nothing
    assert seen["global_seed"] == colmap.SEED
    assert seen["extract"]["extraction_options"].num_threads == colmap.THREADS == 1
    assert seen["match"]["matching_options"].num_threads == 1
    ransac = seen["match"]["verification_options"].ransac
    assert (ransac.random_seed, ransac.num_threads) == (colmap.SEED, 1)
    o = seen["map"]["options"]
    assert (o.num_threads, o.random_seed) == (1, colmap.SEED)
    assert (o.mapper.num_threads, o.mapper.random_seed, o.triangulation.random_seed) == (1, colmap.SEED, colmap.SEED)
