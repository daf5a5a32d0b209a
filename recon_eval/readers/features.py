"""Keypoints and putative matches of a feature pipeline, in recon_eval's own plain format
(docs/features.md, "File format"):

* ``RESULT/keypoints/<view>.txt`` (or ``.npy``): one keypoint per row, columns ``x y`` in pixels,
  then any number of extra columns (scale, angle, response...) that are ignored. Text: whitespace
  or commas between columns, ``#`` starts a comment, blank lines are skipped. ``.npy``: a float or
  integer array of shape (N, k), k >= 2.
* ``RESULT/matches/<view_i>__<view_j>.txt`` (or ``.npy``): one putative match per row,
  ``index_i index_j``, 0-based row indices into the keypoint files of view i and view j (i -> j as
  in the dataset pair). Integers; integral floats (``numpy.savetxt``'s default format) are
  accepted.

Pixels are OpenCV's (the centre of the top-left pixel is (0, 0)) unless ``pixel_origin="corner"``
says that the tool puts the top-left pixel's *corner* at (0, 0) (COLMAP, VLFeat): 0.5 is then
subtracted on reading, by :func:`scenegen.geometry.conventions.opencv_from_colmap_pixels`.

A view without a keypoint file has 0 keypoints and a pair without a match file has 0 matches: both
are scored (as failures), and listed, never dropped. Every problem is an
:class:`recon_eval.errors.InputError` naming the file, the line (text) or row (.npy), and what was
expected.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.npy import read_npy
from recon_eval.readers.text import read_text
from scenegen.geometry.conventions import opencv_from_colmap_pixels

PIXEL_ORIGINS = ("center", "corner")
SUFFIXES = (".txt", ".npy")
KEYPOINTS_DIR = "keypoints"
MATCHES_DIR = "matches"
#: Separator between the two view names of a match file: ``<view_i>__<view_j>``.
PAIR_SEP = "__"


def match_stem(i: str, j: str) -> str:
    return f"{i}{PAIR_SEP}{j}"


def _rows(path: Path, what: str):
    """(line number, tokens) of each non-empty line, comments stripped."""
    for n, line in enumerate(read_text(path, what).splitlines(), 1):
        tok = line.split("#", 1)[0].replace(",", " ").split()
        if tok:
            yield n, tok


def _check_origin(pixel_origin: str) -> None:
    if pixel_origin not in PIXEL_ORIGINS:
        raise InputError(f"pixel_origin must be one of {PIXEL_ORIGINS}, got {pixel_origin!r}")


def read_keypoints(path, pixel_origin: str = "center") -> np.ndarray:
    """Keypoints (N, 2) float64, OpenCV pixels, from a ``.txt`` or ``.npy`` keypoint file."""
    _check_origin(pixel_origin)
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected keypoints: rows of x y [extra columns])")
    if p.suffix.lower() == ".npy":
        a = read_npy(p)
        if a.size == 0:  # an empty array of any shape: no keypoint
            a = np.zeros((0, 2))
        if a.ndim != 2 or a.shape[1] < 2:
            raise InputError(f"{p}: expected an array of shape (N, k), k >= 2 (x y [extra columns]), got {a.shape}")
        xy = a[:, :2].copy()
        bad = np.flatnonzero(~np.all(np.isfinite(xy), axis=1))
        if len(bad):
            raise InputError(f"{p}: row {bad[0]}: x y must be finite numbers, got {xy[bad[0]].tolist()}")
    else:
        pts = []
        for n, tok in _rows(p, "keypoints as text"):
            if len(tok) < 2:
                raise InputError(f"{p}:{n}: expected at least 2 columns (x y [extra columns]), got {len(tok)}")
            try:
                x, y = float(tok[0]), float(tok[1])
            except ValueError:
                raise InputError(f"{p}:{n}: expected numbers x y, got {tok[0]!r} {tok[1]!r}") from None
            if not (np.isfinite(x) and np.isfinite(y)):
                raise InputError(f"{p}:{n}: x y must be finite numbers, got {tok[0]} {tok[1]}")
            pts.append((x, y))
        xy = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    if pixel_origin == "corner":
        xy = opencv_from_colmap_pixels(xy)
    return xy


def _index(value: float, where: str, col: str, n_kp: int, kp_file) -> int:
    """``value`` as a keypoint index; ``where`` ("file:line" or "file: row r") names it in errors."""
    if not (np.isfinite(value) and float(value).is_integer()):
        raise InputError(f"{where}: {col} must be an integer keypoint index, got {value!r}")
    k = int(value)
    if not 0 <= k < n_kp:
        src = kp_file if kp_file is not None else "its keypoint file"
        raise InputError(f"{where}: {col} {k} out of range: {src} has {n_kp} keypoints (valid 0..{n_kp - 1})")
    return k


def read_matches(path, n_i: int, n_j: int, kp_file_i=None, kp_file_j=None) -> np.ndarray:
    """Putative matches (M, 2) int64 ``index_i index_j`` from a ``.txt`` or ``.npy`` match file,
    checked against the keypoint counts ``n_i``, ``n_j`` (``kp_file_*`` only name the files in
    messages)."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected matches: rows of index_i index_j)")
    out = []
    if p.suffix.lower() == ".npy":
        a = read_npy(p)
        if a.size == 0:
            return np.zeros((0, 2), dtype=np.int64)
        if a.ndim != 2 or a.shape[1] != 2:
            raise InputError(f"{p}: expected an array of shape (M, 2) (index_i index_j), got {a.shape}")
        for r, (a_i, a_j) in enumerate(a):
            out.append((_index(a_i, f"{p}: row {r}", "index_i", n_i, kp_file_i),
                        _index(a_j, f"{p}: row {r}", "index_j", n_j, kp_file_j)))
    else:
        for n, tok in _rows(p, "matches as text"):
            if len(tok) != 2:
                raise InputError(f"{p}:{n}: expected 2 columns (index_i index_j), got {len(tok)}")
            vals = []
            for t, col in zip(tok, ("index_i", "index_j")):
                try:
                    vals.append(float(t))
                except ValueError:
                    raise InputError(f"{p}:{n}: {col} must be an integer keypoint index, got {t!r}") from None
            out.append((_index(vals[0], f"{p}:{n}", "index_i", n_i, kp_file_i),
                        _index(vals[1], f"{p}:{n}", "index_j", n_j, kp_file_j)))
    return np.asarray(out, dtype=np.int64).reshape(-1, 2)


def find_file(folder: Path, stem: str) -> Path | None:
    """``folder/stem.txt`` or ``folder/stem.npy``; None if neither; an error if both (ambiguous)."""
    found = [folder / (stem + s) for s in SUFFIXES if (folder / (stem + s)).is_file()]
    if len(found) > 1:
        raise InputError(f"{found[0]} and {found[1]}: both exist; keep one")
    return found[0] if found else None


@dataclass(frozen=True)
class FeatureFiles:
    """What a result folder holds for the asked views and pairs. ``keypoints``: view -> (N, 2)
    float64 OpenCV px ((0, 2) without a file); ``matches``: (i, j) -> (M, 2) int64 ((0, 2) without
    a file); ``files``: view or ``i__j`` -> the path read; ``unused_files``: files under keypoints/
    and matches/ that no asked view or pair reads (relative to ``root``)."""

    root: Path
    pixel_origin: str
    keypoints: dict
    matches: dict
    files: dict
    views_without_keypoints: tuple
    pairs_without_matches: tuple
    unused_files: tuple


def read_feature_files(root, views, pairs, pixel_origin: str = "center") -> FeatureFiles:
    """Read the keypoints of ``views`` and the matches of ``pairs`` ((i, j) tuples) from a result
    folder (module docstring)."""
    _check_origin(pixel_origin)
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{root}: no such folder (expected a feature result: keypoints/<view>.txt, "
                         "matches/<view_i>__<view_j>.txt)")
    kdir, mdir = root / KEYPOINTS_DIR, root / MATCHES_DIR
    if not kdir.is_dir():
        raise InputError(f"{root}: no {KEYPOINTS_DIR}/ folder (expected keypoints/<view>.txt or .npy)")
    kp, files, missing_kp = {}, {}, []
    for v in dict.fromkeys(list(views) + [x for pr in pairs for x in pr]):
        f = find_file(kdir, v)
        files[v] = f
        if f is None:
            missing_kp.append(v)
            kp[v] = np.zeros((0, 2))
        else:
            kp[v] = read_keypoints(f, pixel_origin)
    matches, missing_m = {}, []
    for i, j in pairs:
        stem = match_stem(i, j)
        f = find_file(mdir, stem) if mdir.is_dir() else None
        files[stem] = f
        if f is None:
            rev = find_file(mdir, match_stem(j, i)) if mdir.is_dir() else None
            if rev is not None and (j, i) not in pairs:
                raise InputError(f"{rev}: the dataset pair is ({i}, {j}): name the file {stem}{rev.suffix} with "
                                 f"columns index_{i} index_{j}")
            missing_m.append(stem)
            matches[(i, j)] = np.zeros((0, 2), dtype=np.int64)
            continue
        for v in (i, j):
            if files[v] is None:
                raise InputError(f"{f}: matches need the keypoints of view {v!r}: no {kdir / v}.txt or .npy")
        matches[(i, j)] = read_matches(f, len(kp[i]), len(kp[j]), files[i], files[j])
    used = {f for f in files.values() if f is not None}
    unused = sorted(str(f.relative_to(root)) for d in (kdir, mdir) if d.is_dir() for f in sorted(d.iterdir())
                    if f.suffix.lower() in SUFFIXES and f not in used)
    return FeatureFiles(root, pixel_origin, kp, matches, files, tuple(missing_kp), tuple(missing_m), tuple(unused))
