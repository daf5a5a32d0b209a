"""scenegen.io: atomic writes and lossless round trips (bit-exact, not approximately equal)."""
import hashlib
import os

import cv2
import numpy as np
import OpenEXR
import pytest

from scenegen.dataset import codecs as sio, files


def _temp_files(directory):
    return [p for p in directory.rglob("*") if p.name.endswith(files.TEMP_SUFFIX)]


def _bits_equal(a, b):
    """Bit-for-bit equality (NaN payloads, -0.0 and infinities included)."""
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def _awkward_float32(shape, seed=0):
    """Random float32 values plus every special value: +-inf, quiet NaN, a NaN with a payload,
    -0.0, the smallest denormal and the largest finite float."""
    a = np.random.default_rng(seed).standard_normal(shape).astype(np.float32) * 1e3
    special = np.array([0x7F800000, 0xFF800000, 0x7FC00000, 0x7FC00123, 0x80000000, 0x00000001,
                        0x7F7FFFFF], dtype=np.uint32).view(np.float32)
    a.reshape(-1)[: special.size] = special
    return a


class TestAtomicWrite:
    def test_creates_parents_and_writes(self, tmp_path):
        p = tmp_path / "a" / "b" / "f.bin"
        files.atomic_write_bytes(p, b"hello")
        assert p.read_bytes() == b"hello"
        assert _temp_files(tmp_path) == []

    def test_replaces_existing(self, tmp_path):
        p = tmp_path / "f.bin"
        files.atomic_write_bytes(p, b"old")
        files.atomic_write_bytes(p, b"new content")
        assert p.read_bytes() == b"new content"

    def test_writer_raising_midway_keeps_old_file(self, tmp_path):
        p = tmp_path / "f.bin"
        files.atomic_write_bytes(p, b"old content")

        def half_then_fail(f):
            f.write(b"partial ")
            raise RuntimeError("disk on fire")

        with pytest.raises(RuntimeError, match="disk on fire"):
            files.atomic_write(p, half_then_fail)
        assert p.read_bytes() == b"old content"
        assert sorted(x.name for x in tmp_path.iterdir()) == ["f.bin"]

    def test_writer_raising_leaves_no_file_when_none_existed(self, tmp_path):
        p = tmp_path / "f.bin"
        with pytest.raises(KeyboardInterrupt):
            files.atomic_write(p, lambda f: (f.write(b"x"), (_ for _ in ()).throw(KeyboardInterrupt)))
        assert list(tmp_path.iterdir()) == []

    def test_encoder_failure_never_touches_target(self, tmp_path):
        p = tmp_path / "img.png"
        sio.write_png(p, np.zeros((2, 2), np.uint8))
        before = p.read_bytes()
        with pytest.raises(TypeError):
            sio.write_png(p, np.zeros((2, 2), np.float32))
        assert p.read_bytes() == before

    def test_permissions_follow_umask(self, tmp_path):
        old = os.umask(0o022)
        try:
            files.atomic_write_bytes(tmp_path / "f", b"x")
        finally:
            os.umask(old)
        assert (tmp_path / "f").stat().st_mode & 0o777 == 0o644

    def test_remove_stale_temp_files(self, tmp_path):
        stale = tmp_path / "sub" / f".x.png.abc{files.TEMP_SUFFIX}"
        stale.parent.mkdir()
        stale.write_bytes(b"partial")
        keep = tmp_path / "sub" / ".hidden"
        keep.write_bytes(b"mine")
        assert files.remove_stale_temp_files(tmp_path) == [stale]
        assert not stale.exists() and keep.exists()


class TestHash:
    def test_sha256_file(self, tmp_path):
        data = os.urandom(3 << 20)  # spans several read chunks
        (tmp_path / "f").write_bytes(data)
        assert files.sha256_file(tmp_path / "f") == hashlib.sha256(data).hexdigest()
        assert files.sha256_bytes(data) == hashlib.sha256(data).hexdigest()


class TestJson:
    def test_canonical_bytes_independent_of_insertion_order(self):
        a = {"b": 1, "a": {"y": [1.5, 2], "x": None}}
        b = {"a": {"x": None, "y": [1.5, 2]}, "b": 1}
        assert sio.encode_json(a) == sio.encode_json(b)
        assert sio.encode_json(a).decode() == (
            '{\n  "a": {\n    "x": null,\n    "y": [\n      1.5,\n      2\n    ]\n  },\n  "b": 1\n}\n')

    def test_floats_round_trip_exactly(self, tmp_path):
        values = [0.1, 1 / 3, 1e-300, -0.0, 5e-324, 1.7976931348623157e308, 123456789.123456789]
        sio.write_json(tmp_path / "f.json", {"v": values})
        back = sio.read_json(tmp_path / "f.json")["v"]
        assert _bits_equal(np.array(back), np.array(values))

    def test_numpy_values(self):
        obj = {"f32": np.float32(0.1), "i": np.int64(3), "b": np.bool_(True), "a": np.eye(2)}
        assert sio.encode_json(obj) == sio.encode_json(
            {"f32": float(np.float32(0.1)), "i": 3, "b": True, "a": [[1.0, 0.0], [0.0, 1.0]]})

    def test_nan_and_sets_refused(self):
        with pytest.raises(ValueError, match="NaN"):
            sio.encode_json({"x": float("nan")})
        with pytest.raises(TypeError, match="sets"):
            sio.encode_json({"x": {1, 2}})


class TestPng:
    @pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
    @pytest.mark.parametrize("shape", [(5, 7), (5, 7, 3)])
    def test_round_trip(self, tmp_path, dtype, shape):
        img = np.random.default_rng(1).integers(0, np.iinfo(dtype).max, shape, endpoint=True,
                                                dtype=dtype)
        sio.write_png(tmp_path / "i.png", img)
        assert _bits_equal(sio.read_png(tmp_path / "i.png"), img)

    def test_rgb_order_on_disk(self, tmp_path):
        img = np.zeros((1, 1, 3), np.uint8)
        img[..., 0] = 255  # red
        sio.write_png(tmp_path / "r.png", img)
        bgr = cv2.imread(str(tmp_path / "r.png"), cv2.IMREAD_UNCHANGED)
        assert bgr[0, 0].tolist() == [0, 0, 255]  # any PNG reader sees red

    @pytest.mark.parametrize("bad", [np.zeros((2, 2), np.float32), np.zeros((2, 2, 4), np.uint8),
                                     np.zeros((0, 2), np.uint8)])
    def test_refused(self, tmp_path, bad):
        with pytest.raises((TypeError, ValueError)):
            sio.write_png(tmp_path / "x.png", bad)


class TestExr:
    def test_float32_bit_exact_with_inf_nan(self, tmp_path):
        ch = {"depth_z": _awkward_float32((6, 9)), "P_world.X": _awkward_float32((6, 9), 2)}
        sio.write_exr(tmp_path / "t.exr", ch)
        back = sio.read_exr(tmp_path / "t.exr")
        assert set(back) == set(ch)
        for k in ch:
            assert _bits_equal(back[k], ch[k]), k

    def test_uint32_full_range(self, tmp_path):
        ids = np.random.default_rng(3).integers(0, 2**32, (4, 5), dtype=np.uint32)
        ids[0, :2] = [0, 2**32 - 1]
        sio.write_exr(tmp_path / "ids.exr", {"object_id": ids, "depth": np.ones((4, 5), np.float32)})
        back = sio.read_exr(tmp_path / "ids.exr")
        assert _bits_equal(back["object_id"], ids)

    def test_stored_as_float_and_uint_with_zip(self, tmp_path):
        sio.write_exr(tmp_path / "t.exr", {"a": np.zeros((2, 3), np.float32),
                                           "b": np.zeros((2, 3), np.uint32)})
        f = OpenEXR.File(str(tmp_path / "t.exr"), separate_channels=True)
        assert f.header()["compression"] == OpenEXR.ZIP_COMPRESSION
        types = {k: c.type() for k, c in f.channels().items()}
        assert types == {"a": OpenEXR.FLOAT, "b": OpenEXR.UINT}

    def test_deterministic_bytes(self):
        ch = {"R": _awkward_float32((8, 8)), "G": _awkward_float32((8, 8), 1)}
        assert sio.encode_exr(ch) == sio.encode_exr(dict(reversed(list(ch.items()))))

    @pytest.mark.parametrize("dtype", [np.float64, np.float16, np.int32])
    def test_lossy_or_unsupported_dtypes_refused(self, dtype):
        with pytest.raises(TypeError, match="float32 or uint32"):
            sio.encode_exr({"a": np.zeros((2, 2), dtype)})

    def test_shape_mismatch_refused(self):
        with pytest.raises(ValueError, match="shape"):
            sio.encode_exr({"a": np.zeros((2, 2), np.float32), "b": np.zeros((2, 3), np.float32)})

    def test_corrupt_file_is_value_error(self, tmp_path):
        (tmp_path / "x.exr").write_bytes(b"not an exr")
        with pytest.raises(ValueError, match="not a readable EXR"):
            sio.read_exr(tmp_path / "x.exr")


class TestChannels:
    def test_pack_unpack_round_trip(self):
        p = _awkward_float32((3, 4, 3))
        ch = sio.pack_channels("P_world", p)
        assert list(ch) == ["P_world.X", "P_world.Y", "P_world.Z"]
        assert _bits_equal(sio.unpack_channels(ch, "P_world"), p)

    def test_uv_and_bare_names(self):
        uv = _awkward_float32((3, 4, 2))
        assert list(sio.pack_channels("uv", uv)) == ["uv.U", "uv.V"]
        rgb = _awkward_float32((3, 4, 3))
        ch = sio.pack_channels("", rgb, "RGB")
        assert list(ch) == ["R", "G", "B"]
        assert _bits_equal(sio.unpack_channels(ch, "", "RGB"), rgb)

    def test_missing_channel_named(self):
        with pytest.raises(KeyError, match="N_cam.Z"):
            sio.unpack_channels({"N_cam.X": 0, "N_cam.Y": 0}, "N_cam")


class TestNpy:
    def test_round_trip(self, tmp_path):
        a = _awkward_float32((3, 4))
        sio.write_npy(tmp_path / "a.npy", a)
        assert _bits_equal(sio.read_npy(tmp_path / "a.npy"), a)

    def test_no_pickles(self, tmp_path):
        with pytest.raises(ValueError):
            sio.write_npy(tmp_path / "o.npy", np.array([{"a": 1}], dtype=object))
        assert not (tmp_path / "o.npy").exists()


class TestPfm:
    def test_round_trip_bottom_row_first_and_inf(self, tmp_path):
        a = np.arange(12, dtype=np.float32).reshape(3, 4)
        a[0, 1] = np.inf
        data = sio.encode_pfm(a)
        assert data.startswith(b"Pf\n4 3\n-1.0\n")
        assert np.frombuffer(data[len(b"Pf\n4 3\n-1.0\n"):], "<f4")[:4].tolist() == a[2].tolist()  # bottom row first
        sio.write_pfm(tmp_path / "d.pfm", a)
        assert np.array_equal(sio.read_pfm(tmp_path / "d.pfm"), a)

    def test_colour_big_endian_and_loose_whitespace(self):
        a = np.random.default_rng(0).random((2, 3, 3)).astype(np.float32)
        data = b"PF  3\t2\n1.0\n" + np.ascontiguousarray(a[::-1]).astype(">f4").tobytes()
        assert np.array_equal(sio.decode_pfm(data), a)

    def test_nan_is_written_as_unknown(self):
        assert np.isinf(sio.decode_pfm(sio.encode_pfm(np.array([[np.nan]]))))[0, 0]

    @pytest.mark.parametrize("data, msg", [(b"P6\n1 1\n-1\n" + b"\0" * 4, "not a PFM"),
                                           (b"Pf\n4 4\n-1.0\n" + b"\0" * 8, "truncated"),
                                           (b"Pf\nx 1\n-1\n", "not a PFM")])
    def test_errors(self, tmp_path, data, msg):
        (tmp_path / "bad.pfm").write_bytes(data)
        with pytest.raises(ValueError, match=msg) as e:
            sio.read_pfm(tmp_path / "bad.pfm")
        assert "bad.pfm" in str(e.value)


class TestKitti:
    def test_round_trip_and_invalid_values(self):
        d = np.array([[0.0, 1.0 / 512, 3.25, 255.99], [np.inf, -1.0, 256.0, 1.0]])
        q = sio.kitti_disparity_array(d, valid=np.array([[1, 1, 1, 1], [1, 1, 1, 0]], bool))
        # 0 and 1/512 round to 0 (invalid), inf/negative invalid, 256 does not fit, masked invalid
        assert q.tolist() == [[0, 0, 832, 65533], [0, 0, 0, 0]]
        disp, ok = sio.decode_kitti_disparity(sio.encode_kitti_disparity(d))
        assert ok.tolist() == [[False, False, True, True], [False, False, False, True]]
        assert disp[0, 2] == 3.25 and disp[1, 3] == 1.0

    def test_refuses_non_uint16(self):
        with pytest.raises(ValueError, match="uint16"):
            sio.disparity_from_kitti_array(np.zeros((2, 2), np.uint8))


class TestSintel:
    """The Sintel SDK's sintel_io.py layout: float32 tag 202021.25, then (.dpt) int32 W, H and
    float32 rows, (.cam) M (3x3) and N (3x4) float64, little-endian."""

    def test_dpt_round_trip_and_layout(self):
        d = _awkward_float32((3, 5))
        data = sio.encode_dpt(d)
        assert data[:4] == b"PIEH" and np.frombuffer(data, "<i4", 2, 4).tolist() == [5, 3] and len(data) == 12 + 60
        assert np.array_equal(sio.decode_dpt(data).view(np.uint32), d.view(np.uint32))

    def test_cam_round_trip_and_layout(self):
        M, N = np.arange(9.0).reshape(3, 3) / 7, np.arange(12.0).reshape(3, 4) / 3
        data = sio.encode_cam(M, N)
        assert data[:4] == b"PIEH" and len(data) == 4 + 8 * 21
        assert np.array_equal(np.frombuffer(data, "<f8", 9, 4).reshape(3, 3), M)
        got = sio.decode_cam(data)
        assert np.array_equal(got[0], M) and np.array_equal(got[1], N)

    @pytest.mark.parametrize("data, msg", [(b"PIEX" + bytes(168), "not a Sintel"), (b"PIEH" + bytes(10), "bytes")])
    def test_errors(self, data, msg):
        with pytest.raises(ValueError, match=msg):
            sio.decode_cam(data)
        with pytest.raises(ValueError, match=msg if msg != "bytes" else "dpt"):
            sio.decode_dpt(data)


def test_stereo_motion_channels_round_trip():
    from scenegen.dataset.crossview import Correspondence
    from scenegen.dataset.sequence import (
        MotionTruth,
        StereoMotionTruth,
        decode_stereo_motion_channels,
        encode_stereo_motion_channels,
    )

    rng = np.random.default_rng(1)
    f32 = lambda *s: rng.standard_normal(s).astype(np.float32).astype(np.float64)  # noqa: E731
    c = Correspondence(f32(4, 5, 2), f32(4, 5), rng.integers(0, 4, (4, 5)).astype(np.uint8))
    m = StereoMotionTruth(MotionTruth(c, f32(4, 5, 3)), rng.integers(0, 4, (4, 5)).astype(np.uint8), f32(4, 5))
    back = decode_stereo_motion_channels(sio.decode_exr(sio.encode_exr(encode_stereo_motion_channels(m))))
    for got, want in ((back.left.correspondence.uv, c.uv), (back.left.correspondence.z, c.z),
                      (back.state, c.state), (back.state_right, m.state_right), (back.disparity, m.disparity),
                      (back.left.scene_flow, m.left.scene_flow)):
        assert np.array_equal(got, want)
    assert np.array_equal(back.visible_both, (c.state == 1) & (m.state_right == 1))
    with pytest.raises(KeyError, match="state_right"):
        decode_stereo_motion_channels({k: v for k, v in encode_stereo_motion_channels(m).items() if k != "state_right"})
