"""NPY / NPZ decoding (scenegen.dataset.codecs.npy): what numpy's np.load reads, bit for bit,
and every declared array size checked against the file and the limit before numpy allocates
(issue 25: a 128-byte header claiming 2e10 float32 asked for 74.5 GiB)."""
import io
import zipfile

import numpy as np
import pytest

from scenegen.dataset.codecs import decode_npy, decode_npz, encode_npy, read_npz
from scenegen.dataset.codecs import npy


def _header(shape, descr="<f4") -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False, "shape": shape})
    return buf.getvalue()


ARRAYS = {"f": np.arange(12, dtype=np.float32).reshape(3, 4),
          "fortran": np.asfortranarray(np.arange(6.0).reshape(2, 3)),
          "scalar": np.array(2.5), "empty": np.zeros((0, 3)), "text": np.array(["cam_0000", "cam_0001"]),
          "big_endian": np.arange(4, dtype=">i4"), "bool": np.array([True, False])}


@pytest.mark.parametrize("savez", [np.savez, np.savez_compressed])
def test_npz_decodes_as_np_load_does(savez):
    buf = io.BytesIO()
    savez(buf, **ARRAYS)
    got = decode_npz(buf.getvalue())
    with np.load(io.BytesIO(buf.getvalue()), allow_pickle=False) as z:
        assert list(got) == z.files
        for k in z.files:
            assert got[k].dtype == z[k].dtype and got[k].shape == z[k].shape and got[k].tobytes() == z[k].tobytes()


def test_npy_round_trip_of_every_kind():
    for a in ARRAYS.values():
        b = decode_npy(encode_npy(a))
        assert b.dtype == a.dtype and b.shape == a.shape and np.array_equal(b, a)


@pytest.mark.parametrize("data,fragment", [
    (_header((20_000_000_000,)),
     "declares shape (20000000000,) of float32 (80,000,000,000 bytes), but the file holds 0"),
    (_header((3, 2**30)), "(12,884,901,888 bytes)"),
    (encode_npy(np.zeros(10))[:-1], "(80 bytes), but the file holds 79 bytes"),
    (_header((-5,)), "expected non-negative dimensions"),
    (b"\x93NUMPY\x03\x00" + b"\x00" * 20, "NPY format version 3.0 (expected 1.0 or 2.0)"),
    (b"\x93NUMPY\x01\x00\x04\x00{}  ", "Header does not contain the correct keys"),  # numpy's own check
])
def test_npy_headers_are_checked_before_allocating(data, fragment):
    with pytest.raises(ValueError) as e:
        decode_npy(data)
    assert fragment in str(e.value)


def test_npz_members_are_checked_alone_and_together(tmp_path, monkeypatch):
    def npz(members, compression=zipfile.ZIP_STORED):
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w", compression=compression) as z:
            for name, data in members.items():
                z.writestr(name, data)
        return buf.getvalue()

    for compression in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
        with pytest.raises(ValueError, match="member 'a.npy': the header declares shape"):
            decode_npz(npz({"a.npy": _header((20_000_000_000,))}, compression))
    # each member within the limit, the two together over it (the limit lowered to 1000 bytes for the test)
    monkeypatch.setattr(npy, "MAX_ARRAY_BYTES", 1000)
    members = {"a.npy": encode_npy(np.zeros(600, np.uint8)), "b.npy": encode_npy(np.zeros(600, np.uint8))}
    assert decode_npz(npz({"a.npy": members["a.npy"]}))["a"].shape == (600,)
    with pytest.raises(ValueError, match="member 'b.npy': the arrays declare 1,200 bytes together"):
        decode_npz(npz(members, zipfile.ZIP_DEFLATED))
    with pytest.raises(ValueError, match=r"keys \['tracks'\] missing"):
        decode_npz(npz({"a.npy": encode_npy(np.zeros(2))}), required=("tracks",))
    with pytest.raises(ValueError, match="not a readable NPZ archive"):
        decode_npz(b"PK\x03\x04 not really")
    (tmp_path / "x.npz").write_bytes(b"garbage")
    with pytest.raises(ValueError, match="x.npz: not a readable NPZ archive"):
        read_npz(tmp_path / "x.npz")
