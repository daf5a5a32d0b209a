"""Environment maps are read as the renderer reads them (scenegen.assets.envmap): the size from
the header before any pixel is allocated, then the whole image decoded; what the check accepts
and refuses is what Mitsuba's own envmap accepts and refuses (render-marked), except that the
check also refuses what Mitsuba would take silently (NaN radiance) or fail to allocate."""
import time
import tracemalloc

import cv2
import numpy as np
import pytest

from scenegen.assets.envmap import check_envmap, hdr_size
from scenegen.dataset.codecs import pack_channels, write_exr

HDR = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"


def test_the_radiance_header_gives_the_size_or_a_reason():
    assert hdr_size(HDR + b"-Y 8 +X 16\n") == (16, 8)
    assert hdr_size(b"#?RGBE\nEXPOSURE=1\n\n-Y 3 +X 5\r\n") == (5, 3)
    for head, why in [(b"P6\n4 4\n", "not a Radiance HDR file"), (b"#?RADIANCE\nFORMAT=x\n", "does not end"),
                      (HDR + b"+X 16 -Y 8\n", "resolution line"), (HDR + b"-Y 1e9 +X 2\n", "resolution line")]:
        with pytest.raises(ValueError, match=why):
            hdr_size(head)


def test_a_huge_header_is_refused_before_anything_is_allocated(tmp_path):
    p = tmp_path / "huge.hdr"
    p.write_bytes(HDR + b"-Y 100000 +X 100000\n" + bytes(16))
    tracemalloc.start()
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="100000 x 100000 pixels by its header; expected 1 to 67,108,864"):
        check_envmap(p)
    seconds = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert seconds < 0.5 and peak < 1 << 20, (seconds, peak)  # measured ~1 ms, ~70 kB


def _maps(d):
    """name -> path of good and bad maps."""
    rgb = np.linspace(0.1, 2.0, 8 * 16 * 3, dtype=np.float32).reshape(8, 16, 3)
    cv2.imwrite(str(d / "ok.hdr"), rgb)
    write_exr(d / "ok.exr", pack_channels("", rgb, "RGB"))
    cv2.imwrite(str(d / "ok.png"), (np.clip(rgb, 0, 1) * 255).astype(np.uint8))
    cv2.imwrite(str(d / "ok.jpg"), (np.clip(rgb, 0, 1) * 255).astype(np.uint8))
    (d / "text.exr").write_text("not an EXR file\n")
    (d / "empty.hdr").write_bytes(b"")
    (d / "wide.hdr").write_bytes(HDR + b"-Y 1 +X 100000\n" + bytes(16))
    (d / "cut.hdr").write_bytes((d / "ok.hdr").read_bytes()[:-40])
    (d / "bad.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(200)))
    return {p.name: p for p in d.iterdir()}


def test_good_maps_pass_and_bad_ones_name_the_file(tmp_path):
    maps = _maps(tmp_path)
    assert check_envmap(maps["ok.hdr"]) == (16, 8) and check_envmap(maps["ok.exr"]) == (16, 8)
    assert check_envmap(maps["ok.png"]) == (16, 8) and check_envmap(maps["ok.jpg"]) == (16, 8)
    for name in ("text.exr", "empty.hdr", "wide.hdr", "cut.hdr", "bad.png"):
        with pytest.raises(ValueError, match=f"environment map '.*{name}'"):
            check_envmap(maps[name])


@pytest.mark.render
def test_the_check_agrees_with_mitsubas_envmap(tmp_path):
    import mitsuba as mi

    from scenegen.render.backend import load_mitsuba

    load_mitsuba("scalar_rgb")
    for name, p in sorted(_maps(tmp_path).items()):
        try:
            check_envmap(p)
            ours = True
        except ValueError:
            ours = False
        try:
            mi.load_dict({"type": "envmap", "filename": str(p)})
            theirs = True
        except RuntimeError:
            theirs = False
        assert ours == theirs, (name, ours, theirs)
