"""Seeds of the imaging chain's random draws.

Every random draw comes from ``numpy.random.default_rng(SeedSequence(...))`` with an entropy
that names what it is for, so a draw never depends on how many numbers an earlier stage took:

* temporal noise (changes every frame): ``[frame_seed, crc32(stage)]`` where
  ``frame_seed = frame_seed(scene_seed, view_index)``;
* fixed-pattern noise (PRNU, DSNU; the same in every frame of one camera):
  ``[fixed_pattern_seed, crc32(stage)]`` where the spec derives ``fixed_pattern_seed`` from the
  camera's name (:func:`fixed_pattern_seed_for`).

The rule is :mod:`scenegen.geometry.seeds`' (crc32 is zlib's: stable across platforms and
Python versions, unlike ``hash``); this module names the parts.
"""
from __future__ import annotations

import numpy as np

from scenegen.geometry import seeds

#: Stage names of the temporal draws (part of the seed; renaming one changes the noise).
STAGE_SHOT = "shot_noise"
STAGE_DARK_CURRENT = "dark_current"
STAGE_READ = "read_noise"
#: Stage names of the fixed-pattern draws.
STAGE_PRNU = "prnu"
STAGE_DSNU = "dsnu"


def frame_seed(scene_seed: int, view_index: int) -> int:
    """Seed of one frame's temporal noise (0 .. 2**32 - 1), fixed by (scene seed, view index)."""
    return seeds.seed32(scene_seed, view_index, "imaging")


def fixed_pattern_seed_for(camera_name: str) -> int:
    """Default fixed-pattern seed of a camera: crc32 of its name (0 .. 2**32 - 1)."""
    return seeds.name_seed32(camera_name)


def stage_rng(seed: int, stage: str) -> np.random.Generator:
    """The generator of one stage: ``default_rng(SeedSequence([seed, crc32(stage)]))``."""
    return seeds.rng(seed, stage)
