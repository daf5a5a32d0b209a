"""Seeds of the imaging chain's random draws.

Every random draw comes from ``numpy.random.default_rng(SeedSequence(...))`` with an entropy
that names what it is for, so a draw never depends on how many numbers an earlier stage took:

* temporal noise (changes every frame): ``[frame_seed, crc32(stage)]`` where
  ``frame_seed = frame_seed(scene_seed, view_index)``;
* fixed-pattern noise (PRNU, DSNU; the same in every frame of one camera):
  ``[fixed_pattern_seed, crc32(stage)]`` where the spec derives ``fixed_pattern_seed`` from the
  camera's name (:func:`fixed_pattern_seed_for`).

crc32 is zlib's (stable across platforms and Python versions, unlike ``hash``).
"""
from __future__ import annotations

import zlib

import numpy as np

#: Stage names of the temporal draws (part of the seed; renaming one changes the noise).
STAGE_SHOT = "shot_noise"
STAGE_DARK_CURRENT = "dark_current"
STAGE_READ = "read_noise"
#: Stage names of the fixed-pattern draws.
STAGE_PRNU = "prnu"
STAGE_DSNU = "dsnu"


def frame_seed(scene_seed: int, view_index: int) -> int:
    """Seed of one frame's temporal noise (0 .. 2**32 - 1), fixed by (scene seed, view index)."""
    ss = np.random.SeedSequence([int(scene_seed), int(view_index), zlib.crc32(b"imaging")])
    return int(ss.generate_state(1)[0])


def fixed_pattern_seed_for(camera_name: str) -> int:
    """Default fixed-pattern seed of a camera: crc32 of its name (0 .. 2**32 - 1)."""
    return zlib.crc32(camera_name.encode("utf-8"))


def stage_rng(seed: int, stage: str) -> np.random.Generator:
    """The generator of one stage: ``default_rng(SeedSequence([seed, crc32(stage)]))``."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), zlib.crc32(stage.encode())]))
