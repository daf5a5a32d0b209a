import io

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.readers.tracks import read_tracks


def _save(path, **arrays):
    np.savez(path, **arrays)
    return path


def test_own_keys_and_visibility_keys(tmp_path):
    pos = np.arange(24, dtype=np.float32).reshape(3, 4, 2)
    occ = np.zeros((3, 4), bool)
    occ[1, 2] = True
    p, o = read_tracks(_save(tmp_path / "a.npz", tracks_xy=pos, occluded=occ), 3, 4)
    assert p.dtype == np.float64 and np.array_equal(p, pos) and np.array_equal(o, occ)
    p, o = read_tracks(_save(tmp_path / "b.npz", tracks=pos, visibles=~occ), 3, 4)
    assert np.array_equal(o, occ)


def test_errors_name_the_file_and_what_was_expected(tmp_path):
    pos = np.zeros((3, 4, 2))
    occ = np.zeros((3, 4), bool)
    with pytest.raises(InputError, match=r"b\.npz: tracks_xy: expected numbers of shape \(3, 5, 2\)"):
        read_tracks(_save(tmp_path / "b.npz", tracks_xy=pos, occluded=occ), 3, 5)
    with pytest.raises(InputError, match="no track positions.*found occluded"):
        read_tracks(_save(tmp_path / "c.npz", occluded=occ), 3, 4)
    with pytest.raises(InputError, match="no occlusion"):
        read_tracks(_save(tmp_path / "d.npz", tracks=pos), 3, 4)
    with pytest.raises(InputError, match="expected booleans"):
        read_tracks(_save(tmp_path / "e.npz", tracks=pos, occluded=occ + 0.5), 3, 4)
    (tmp_path / "f.npz").write_bytes(b"not a zip")
    with pytest.raises(InputError, match="f.npz: not a readable pickle-free .npz"):
        read_tracks(tmp_path / "f.npz", 3, 4)


def test_pickled_arrays_are_refused(tmp_path):
    buf = io.BytesIO()
    np.savez(buf, tracks=np.array([{"a": 1}], dtype=object), occluded=np.zeros((1, 1), bool))
    (tmp_path / "p.npz").write_bytes(buf.getvalue())
    with pytest.raises(InputError, match="pickle"):
        read_tracks(tmp_path / "p.npz", 1, 1)
