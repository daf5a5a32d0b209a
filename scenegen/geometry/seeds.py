"""How every seed of the project is derived: two rules, one for numpy streams, one for samplers.

A derived seed never depends on how many numbers another stage drew: it is a function of the
user's seed and of names saying what it is for.

* numpy streams: ``SeedSequence([part, ...])`` with integers as they are and strings as their
  zlib crc32 (stable across platforms and Python versions, unlike ``hash``):
  :func:`seed_sequence`, :func:`rng` (a Generator), :func:`seed32` (one uint32 drawn from it).
  Used for spec defaults (``seed32(scene_seed, field_path)``), the imaging chain's frames and
  stages, variants, match sets' defaults and the evaluator's tasks.
* Mitsuba sampler seeds: the first 4 bytes (little-endian) of the SHA-256 of the parts joined by
  ``:`` (:func:`hashed_seed32`): a view's sampler seed is ``hashed_seed32(seed, view_index)``, a
  rectified render's ``hashed_seed32(seed, left_view, side)``.
* :func:`name_seed32`: the crc32 of a name (a camera's default fixed-pattern noise seed).

Changing any rule changes the bytes of every dataset: they are fixed here, and tested.
"""
from __future__ import annotations

import hashlib
import zlib

import numpy as np

SEED_MAX = 2**32 - 1


def name_seed32(name: str) -> int:
    """zlib crc32 of the UTF-8 name (0 .. 2**32 - 1)."""
    return zlib.crc32(name.encode("utf-8"))


def _entropy(parts) -> list[int]:
    return [name_seed32(p) if isinstance(p, str) else int(p) for p in parts]


def seed_sequence(*parts) -> np.random.SeedSequence:
    """``SeedSequence`` of the parts: integers as they are, strings as their crc32."""
    return np.random.SeedSequence(_entropy(parts))


def rng(*parts) -> np.random.Generator:
    """``numpy.random.default_rng(seed_sequence(*parts))``."""
    return np.random.default_rng(seed_sequence(*parts))


def seed32(*parts) -> int:
    """One uint32 (0 .. 2**32 - 1) of ``seed_sequence(*parts)``."""
    return int(seed_sequence(*parts).generate_state(1)[0])


def hashed_seed32(*parts) -> int:
    """The first 4 bytes, little-endian, of SHA-256 of ``":".join(str(p) for p in parts)``."""
    h = hashlib.sha256(":".join(str(p) for p in parts).encode()).digest()
    return int.from_bytes(h[:4], "little")
