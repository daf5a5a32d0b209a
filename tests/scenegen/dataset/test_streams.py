"""Streams beside views (scenegen.dataset.streams, stream_writer, stream_reader): written
atomically and hashed, read back with typed accessors and with plain numpy/json (the format is
readable without this project), deterministic, resumable to the bytes of one run, verified; bad
documents and chunks refused with the file named."""
import io
import json
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from scenegen import dataset as ds
from scenegen.dataset.codecs import decode_npz
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.streams import StreamField, StreamSchema, encode_chunk

sys.path.insert(0, str(Path(__file__).parent))
from test_dataset import all_bytes, new_writer, write_dataset  # noqa: E402

sys.path.insert(0, str(Path(__file__).parents[2] / "hostile"))
from hostile_data import resign  # noqa: E402

SCHEMA = StreamSchema("imu", "imu0", (
    StreamField("accel_mps2", "float64", (3,), "m/s^2", "specific force, IMU frame"),
    StreamField("gyro_rad_s", "float32", (3,), "rad/s", "angular velocity, IMU frame"),
    StreamField("saturated", "bool", (), "flag"),
))


def chunks(n_chunks=3, per=50, rate_hz=200.0):
    rng = np.random.default_rng(3)
    for k in range(n_chunks):
        t = (np.arange(per) + k * per) / rate_hz
        yield t, {"accel_mps2": rng.normal(size=(per, 3)), "gyro_rad_s": rng.normal(size=(per, 3)),
                  "saturated": rng.random(per) < 0.1}


def write_stream(out, stop_after=None, writer=None):
    w = writer or new_writer(out, resume=(out / "manifest.json").exists())
    write_dataset(out, writer=w) if writer is None else None
    sw = ds.StreamWriter(w, "imu0", SCHEMA)
    for k, (t, fields) in enumerate(chunks()):
        if stop_after is not None and k == stop_after:
            w.abort()  # killed here: the chunks so far are in the journal
            return None
        sw.write_chunk(k, t, fields)
    sw.close()
    w.close()
    return out


@pytest.fixture(scope="module")
def streamed(tmp_path_factory):
    return write_stream(tmp_path_factory.mktemp("streams") / "out")


def test_round_trip_with_typed_accessors(streamed):
    d = ds.Dataset(streamed)
    assert d.streams.names == ("imu0",) and d.streams.of_kind("imu") == ("imu0",)
    s = d.streams["imu0"]
    assert (s.kind, s.sensor, s.samples) == ("imu", "imu0", 150)
    want = list(chunks())
    assert np.array_equal(s.time_s, np.concatenate([t for t, _ in want]))
    assert np.array_equal(s.field("accel_mps2"), np.concatenate([f["accel_mps2"] for _, f in want]))
    assert s.field("gyro_rad_s").dtype == np.float32 and s.field("saturated").dtype == bool
    with pytest.raises(KeyError, match="no field 'mag'"):
        s.field("mag")
    with pytest.raises(KeyError, match="no complete stream 'lidar'"):
        d.streams["lidar"]
    assert ds.verify(streamed).ok


def test_readable_without_this_project(streamed):
    doc = json.loads((streamed / "streams/imu0/stream.json").read_text())
    assert doc["schema"]["accel_mps2"] == {"dtype": "float64", "shape": [3], "unit": "m/s^2",
                                           "doc": "specific force, IMU frame"}
    times = []
    for c in doc["chunks"]:
        with np.load(streamed / c["path"], allow_pickle=False) as z:
            assert sorted(z.files) == ["accel_mps2", "gyro_rad_s", "saturated", "time_s"]
            assert len(z["time_s"]) == c["samples"] and z["time_s"][0] == c["first_time_s"]
            times.append(z["time_s"])
    assert np.all(np.diff(np.concatenate(times)) > 0) and doc["samples"] == 150


def test_deterministic_and_a_killed_run_resumes_to_the_same_bytes(tmp_path, streamed):
    assert all_bytes(write_stream(tmp_path / "again")) == all_bytes(streamed)
    out = tmp_path / "killed"
    assert write_stream(out, stop_after=2) is None
    assert "streams" not in ds.Dataset(out).streams.names and not ds.verify(out).ok  # unfinished
    assert all_bytes(write_stream(out)) == all_bytes(streamed)  # --resume: the bytes of one run


def test_a_chunk_with_other_bytes_is_refused_on_resume(tmp_path):
    out = tmp_path / "o"
    write_stream(out, stop_after=1)
    w = new_writer(out, resume=True)
    sw = ds.StreamWriter(w, "imu0", SCHEMA)
    t, fields = next(chunks())
    fields["accel_mps2"] = fields["accel_mps2"] + 1.0
    with pytest.raises(ds.DatasetMismatchError, match="chunk_000000.npz is already recorded"):
        sw.write_chunk(0, t, fields)
    w.abort()


@pytest.mark.parametrize("bad,match", [
    (lambda t, f: (t[::-1], f), "strictly increasing"),
    (lambda t, f: (t, {**f, "accel_mps2": f["accel_mps2"][:, :2]}), "must have shape"),
    (lambda t, f: (t, {k: v for k, v in f.items() if k != "saturated"}), r"missing \['saturated'\]"),
])
def test_bad_chunks_are_refused_naming_what_is_wrong(bad, match):
    t, f = next(chunks())
    with pytest.raises(ValueError, match=match):
        encode_chunk(SCHEMA, *bad(t, f))
    with pytest.raises(ValueError, match="not int32"):
        encode_chunk(StreamSchema("odom", "wheels", (StreamField("ticks", "int32"),)), [0.0, 1.0],
                     {"ticks": np.array([1.0, 2.5])})
    with pytest.raises(ValueError, match="reserved"):
        StreamField("time_s", "float64")


def npz_of(members: dict[str, bytes]) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    return buf.getvalue()


def test_an_npz_member_declaring_more_than_it_holds_is_refused_before_allocation():
    npy = io.BytesIO()
    np.lib.format.write_array(npy, np.zeros(4, np.float32))
    huge = npy.getvalue().replace(b"'shape': (4,), ", b"'shape': (20000000000,), ")  # 80 GB declared
    with pytest.raises(ValueError, match=r"member 'x.npy': the header declares shape \(20000000000,\) of float32"):
        decode_npz(npz_of({"x.npy": huge}))
    pickled = io.BytesIO()
    np.lib.format.write_array(pickled, np.array([{"a": 1}], dtype=object), allow_pickle=True)
    with pytest.raises(ValueError, match="member 'o.npy': an object array"):
        decode_npz(npz_of({"o.npy": pickled.getvalue()}))


def test_a_tampered_stream_document_is_named_by_the_reader_and_verify(tmp_path, streamed):
    import shutil
    out = tmp_path / "t"
    shutil.copytree(streamed, out)
    p = out / "streams/imu0/stream.json"
    doc = json.loads(p.read_text())
    doc["chunks"][1]["path"] = "../../cameras.json"
    p.write_text(json.dumps(doc))
    resign(out)
    with pytest.raises(DatasetError, match=r"stream\.json: stream 'imu0': chunk 1 must be at"):
        ds.Dataset(out).streams["imu0"]
    assert any("stream.json" in x for x in ds.verify(out).problems)
