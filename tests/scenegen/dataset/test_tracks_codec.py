"""The point-track NPZ: round trip, fixed bytes, readable by plain numpy without pickles, the
documented keys, and clear errors."""
import io
import zipfile

import numpy as np
import pytest

from scenegen.dataset.codecs import TRACK_KEYS, TrackSet, decode_tracks, encode_tracks, read_tracks, write_tracks
from scenegen.dataset.layout import tracks_path


def _tracks(n=5, t=4, seed=0):
    rng = np.random.default_rng(seed)
    occ = rng.random((n, t)) < 0.3
    return TrackSet(query_points=np.column_stack([rng.integers(0, t, n), rng.random(n) * 48, rng.random(n) * 64]),
                    tracks_xy=rng.random((n, t, 2)) * 60, occluded=occ, out_of_frame=occ & (rng.random((n, t)) < 0.5),
                    image_size=[64, 48], frame_names=[f"cam_{k:04d}" for k in range(t)])


def test_round_trip_and_fixed_bytes(tmp_path):
    tr = _tracks()
    data = encode_tracks(tr)
    assert data == encode_tracks(_tracks())  # no time stamps in the archive
    back = decode_tracks(data)
    for k in TRACK_KEYS:
        assert np.array_equal(getattr(back, k), getattr(tr, k)) and getattr(back, k).dtype == getattr(tr, k).dtype
    write_tracks(tmp_path / "t.npz", tr)
    assert np.array_equal(read_tracks(tmp_path / "t.npz").tracks_xy, tr.tracks_xy)


def test_plain_numpy_reads_the_documented_keys_without_pickles():
    with np.load(io.BytesIO(encode_tracks(_tracks())), allow_pickle=False) as z:
        assert sorted(z.files) == sorted(TRACK_KEYS)
        assert z["query_points"].shape == (5, 3) and z["query_points"].dtype == np.float32
        assert z["tracks_xy"].shape == (5, 4, 2) and z["tracks_xy"].dtype == np.float32
        assert z["occluded"].dtype == bool and z["out_of_frame"].dtype == bool
        assert z["image_size"].tolist() == [64, 48] and z["frame_names"].dtype.kind == "U"


def test_bad_input_is_refused_with_the_key_named(tmp_path):
    with pytest.raises(ValueError, match="tracks_xy must have shape"):
        TrackSet(query_points=np.zeros((2, 3)), tracks_xy=np.zeros((3, 4, 2)), occluded=np.zeros((2, 4), bool),
                 out_of_frame=np.zeros((2, 4), bool), image_size=[1, 1], frame_names=["a"] * 4)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("query_points.npy", b"")
    with pytest.raises(ValueError, match="missing"):
        decode_tracks(buf.getvalue())
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="bad.npz"):
        read_tracks(tmp_path / "bad.npz")
    assert tracks_path("cam_left") == "sequence/tracks/cam_left.npz"
    with pytest.raises(ValueError):
        tracks_path("../x")


def test_a_visible_point_must_be_finite_on_every_read_and_write():
    """The rule the exports and recon-eval's scoring share (issue 25: all-NaN truth tracks were
    exported with exit 0 while recon-eval refused them): NaN only where the point is occluded."""
    tr = _tracks()
    xy = tr.tracks_xy.copy()
    xy[tr.occluded] = np.nan  # allowed: not visible
    assert len(TrackSet(tr.query_points, xy, tr.occluded, tr.out_of_frame, tr.image_size, tr.frame_names)) == 5
    n, t = np.argwhere(~tr.occluded)[0]
    xy[n, t, 0] = np.nan
    with pytest.raises(ValueError, match=f"track {n} at frame {t} is visible \\(not occluded\\) but not finite"):
        TrackSet(tr.query_points, xy, tr.occluded, tr.out_of_frame, tr.image_size, tr.frame_names)
    q = tr.query_points.copy()
    q[2, 1] = np.inf
    with pytest.raises(ValueError, match="query_points: track 2 is not finite"):
        TrackSet(q, tr.tracks_xy, tr.occluded, tr.out_of_frame, tr.image_size, tr.frame_names)
