"""Lossless EXR codecs and PNG levels for the truth files (not a test; the dataset format does
not change): encoding and decoding time, size, bit-exactness, and whether OpenEXR and OpenCV
read the file.

The data are the demo's truth channels of one view (16 float32 + 2 uint32 channels, 480x360) and
its linear RGB (3 float32 channels), from the truth pass and a 16-spp render. OpenCV reads EXR
only with OPENCV_IO_ENABLE_OPENEXR=1 and only up to 4 channels, so its check uses the RGB file.

Run: .venv/bin/python benchmarks/bench_codecs.py [--repeat 5]
"""
from __future__ import annotations

import argparse
import io
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OPENCV_IO_ENABLE_OPENEXR", "1")  # before cv2 is imported

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, load  # noqa: E402

CODECS = ("NO", "RLE", "ZIPS", "ZIP", "PIZ", "ZSTD", "HTJ2K256", "HTJ2K32")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    import cv2
    import OpenEXR

    from scenegen.dataset.truth import check_truth, truth_float_channels, truth_id_channels
    from scenegen.pipeline.view import render_view_data
    from scenegen.render import load_scene
    from scenegen.spec import load_spec, resolve_views

    spec = load_spec(ROOT / "scenes/demo.yaml")
    view = resolve_views(spec)[1]
    built = load_scene(spec)
    image, linear, truth, _ = render_view_data(spec, built, 1, view, spp=spec.render.spp, seed=spec.render.seed)
    t = check_truth(truth)
    truth_ch = {**truth_float_channels(t), **truth_id_channels(t)}
    rgb_ch = {c: np.ascontiguousarray(linear[..., i]) for i, c in enumerate("RGB")}

    def encode(chans, comp):
        buf = io.BytesIO()
        OpenEXR.File({"compression": comp, "type": OpenEXR.scanlineimage}, dict(chans)).write(buf)  # File() alters the dict
        return buf.getvalue()

    def best(fn):
        fn()
        return statistics.median([timed(fn) for _ in range(args.repeat)])

    def timed(fn):
        s = time.perf_counter()
        fn()
        return time.perf_counter() - s

    print(f"demo view, 480x360: truth = 16 float32 + 2 uint32 channels ({sum(a.nbytes for a in truth_ch.values()) / 2**20:.1f}"
          f" MiB raw), linear = 3 float32 channels; {load()}, OpenEXR {OpenEXR.OPENEXR_VERSION}, OpenCV {cv2.__version__}")
    print(f"  {'codec':9s} {'truth enc ms':>12s} {'dec ms':>7s} {'MiB':>6s} {'exact':>6s} | {'RGB enc ms':>10s} {'MiB':>6s}"
          f" {'OpenCV reads':>12s}")
    tmp = Path(tempfile.mkdtemp())
    for name in CODECS:
        comp = getattr(OpenEXR, f"{name}_COMPRESSION", None)
        if comp is None:
            print(f"  {name:9s} not in this OpenEXR")
            continue
        try:
            data = encode(truth_ch, comp)
        except Exception as e:  # a codec that refuses these channels (e.g. uint32)
            print(f"  {name:9s} refused: {str(e)[:60]}")
            continue
        t_enc = best(lambda: encode(truth_ch, comp))
        back = OpenEXR.File(io.BytesIO(data), separate_channels=True).channels()
        t_dec = best(lambda: OpenEXR.File(io.BytesIO(data), separate_channels=True).channels())
        exact = all(np.array_equal(back[k].pixels.view(np.uint32), v.view(np.uint32)) for k, v in truth_ch.items())
        rgb = encode(rgb_ch, comp)
        t_rgb = best(lambda: encode(rgb_ch, comp))
        p = tmp / f"{name}.exr"
        p.write_bytes(rgb)
        img = cv2.imread(str(p), cv2.IMREAD_UNCHANGED)
        cv_ok = img is not None and np.array_equal(img[..., ::-1].view(np.uint32), linear.view(np.uint32))
        print(f"  {name:9s} {1e3 * t_enc:12.1f} {1e3 * t_dec:7.1f} {len(data) / 2**20:6.2f} {str(exact):>6s} |"
              f" {1e3 * t_rgb:10.1f} {len(rgb) / 2**20:6.2f} {('yes, exact' if cv_ok else 'no'):>12s}")
    for level in (0, 1, 3, 6, 9):  # the image PNG (bytes of the dataset use OpenCV's default)
        flags = [cv2.IMWRITE_PNG_COMPRESSION, level]
        data = cv2.imencode(".png", image[..., ::-1], flags)[1]
        t_png = best(lambda: cv2.imencode(".png", image[..., ::-1], flags))
        print(f"  PNG level {level}: {1e3 * t_png:.1f} ms, {len(data) / 2**10:.0f} KiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
