"""Decoding a bad file prints nothing of the libraries' own (scenegen.quiet): OpenCV's
``[ WARN:0@...]``/``[ERROR:0@...]`` lines and OpenEXR's ``Warning: ...`` (stdout) and
``(EXR_ERR_...)`` (stderr) lines came before our one-line error; the file descriptors and
OpenCV's log level are restored afterwards."""
import io

import cv2
import numpy as np
import OpenEXR
import pytest

from scenegen.assets.textures import load_image
from scenegen.dataset.codecs import decode_exr, decode_png, encode_exr, pack_channels, read_exr
from scenegen.quiet import decode_image, quiet_native_output

PNG_HEAD = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x10\x00\x00\x00\x10\x08\x02\x00\x00\x00\x90\x91h6"


def _exr_bytes():
    return encode_exr(pack_channels("", np.linspace(0, 1, 64 * 64 * 3, dtype=np.float32).reshape(64, 64, 3), "RGB"))


def test_native_lines_are_what_the_helper_silences(capfd):
    """The libraries do print without the helper (so the tests below can fail), and not with it."""
    bad_png = np.frombuffer(b"\x89PNG\r\n\x1a\n" + bytes(range(200)), np.uint8)
    data = _exr_bytes()

    def decode_both():
        cv2.imdecode(bad_png, cv2.IMREAD_UNCHANGED)
        with pytest.raises(Exception):
            OpenEXR.File(io.BytesIO(data[: len(data) // 2]), separate_channels=True).channels()

    decode_both()
    out, err = capfd.readouterr()
    assert "IHDR" in err and "EXR_ERR" in err and "Warning" in out
    with quiet_native_output():
        decode_both()
    assert capfd.readouterr() == ("", "")


def test_bad_png_exr_and_texture_decode_silently(tmp_path, capfd):
    data = _exr_bytes()
    (tmp_path / "half.exr").write_bytes(data[: len(data) // 2])
    (tmp_path / "bad.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(200)))
    (tmp_path / "trunc.png").write_bytes(PNG_HEAD + b"\x00\x00\x01\x00IDAT")
    with pytest.raises(ValueError, match="half.exr: not a readable EXR file"):
        read_exr(tmp_path / "half.exr")
    with pytest.raises(ValueError, match="not a readable EXR file"):
        decode_exr(data[:40])
    with pytest.raises(ValueError, match="not a readable PNG"):
        decode_png((tmp_path / "bad.png").read_bytes())
    for name in ("bad.png", "trunc.png"):
        with pytest.raises(ValueError, match="could not decode"):
            load_image(tmp_path / name)
    assert decode_image(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 100000\n" + bytes(16)) is None
    out, err = capfd.readouterr()
    assert out == "" and err == "", (out, err)


def test_output_and_log_level_are_restored(capfd):
    level = cv2.utils.logging.getLogLevel()
    print("before", flush=True)
    with pytest.raises(RuntimeError):
        with quiet_native_output():
            print("swallowed")
            raise RuntimeError("inside")
    print("after")
    assert capfd.readouterr().out == "before\nafter\n" and cv2.utils.logging.getLogLevel() == level
