import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.readers.correspondence import read_correspondence_map
from scenegen.dataset import codecs as sio
from scenegen.dataset.crossview import OCCLUDED, VISIBLE


def test_read_correspondence_map(tmp_path):
    H, W = 6, 8
    rng = np.random.default_rng(0)
    uv = rng.uniform(-1, 9, size=(H, W, 2))
    state = np.where(rng.random((H, W)) < 0.2, OCCLUDED, VISIBLE)
    sio.write_exr(tmp_path / "c.exr", {"u": uv[..., 0].astype(np.float32), "v": uv[..., 1].astype(np.float32),
                                      "z": np.ones((H, W), np.float32), "state": state.astype(np.uint32)})
    back = read_correspondence_map(tmp_path / "c.exr")
    np.testing.assert_array_equal(back.state, state)
    np.testing.assert_array_equal(back.uv, uv.astype(np.float32).astype(np.float64))  # widened exactly
    np.testing.assert_array_equal(back.z, np.ones((H, W)))
    sio.write_exr(tmp_path / "bad.exr", {"u": np.zeros((2, 2), np.float32)})
    with pytest.raises(InputError, match="bad.exr.*missing"):
        read_correspondence_map(tmp_path / "bad.exr")
    (tmp_path / "junk.exr").write_bytes(b"junk")
    with pytest.raises(InputError, match="junk.exr"):
        read_correspondence_map(tmp_path / "junk.exr")
    with pytest.raises(InputError, match="no such file"):
        read_correspondence_map(tmp_path / "absent.exr")
