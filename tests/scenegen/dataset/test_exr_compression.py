"""render.exr_compression: every choice is lossless and read back by OpenEXR, by OpenCV where the
registry says so (and not where it says not); the default leaves the spec's hash and the bytes."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import OpenEXR
import pytest

from scenegen.dataset.codecs.exr import DEFAULT_EXR_COMPRESSION, EXR_COMPRESSIONS, decode_exr
from scenegen.dataset.view_files import encode_view
from scenegen.spec import parse_spec, spec_sha256, spec_to_dict
from scenegen.spec.model.render import EXR_COMPRESSION_NAMES

sys.path.insert(0, str(Path(__file__).parent))  # the dataset fixtures of test_dataset.py
from test_dataset import make_view  # noqa: E402

_READ_WITH_OPENCV = """
import json, sys
import cv2, numpy as np
out = {}
for path in sys.argv[1:]:
    img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    out[path] = None if img is None else img[..., ::-1].astype(np.float32).view(np.uint32).tolist()
print(json.dumps(out))
"""


def test_the_spec_offers_exactly_the_registry():
    assert set(EXR_COMPRESSION_NAMES) == set(EXR_COMPRESSIONS)
    assert DEFAULT_EXR_COMPRESSION == "zip"


def _header_compression(data: bytes):
    return OpenEXR.File(__import__("io").BytesIO(data), header_only=True).header()["compression"]


def test_every_compression_round_trips_bit_exact_in_openexr_and_opencv(tmp_path):
    view = make_view(3)
    ref = encode_view("v", **view)
    linear_paths = {}
    for name, info in EXR_COMPRESSIONS.items():
        files = encode_view("v", exr_compression=name, **view)
        assert set(files) == set(ref)
        for rel, data in files.items():
            if not rel.endswith(".exr"):
                assert data == ref[rel]  # the PNGs do not depend on it
                continue
            assert _header_compression(data) == getattr(OpenEXR, f"{info.openexr_name}_COMPRESSION")
            back, want = decode_exr(data), decode_exr(ref[rel])
            assert list(back) == list(want)
            for k in want:  # bit for bit, NaN and infinities included
                assert back[k].dtype == want[k].dtype
                assert np.array_equal(back[k].view(np.uint32), want[k].view(np.uint32)), (name, rel, k)
            if name == DEFAULT_EXR_COMPRESSION:
                assert data == ref[rel]  # the default is the format's ZIP, byte for byte
        lin = tmp_path / f"{name}.exr"
        lin.write_bytes(files["images/v_linear.exr"])
        linear_paths[name] = str(lin)
    env = dict(os.environ, OPENCV_IO_ENABLE_OPENEXR="1")  # read by OpenCV when it first decodes an EXR
    r = subprocess.run([sys.executable, "-c", _READ_WITH_OPENCV, *linear_paths.values()], env=env,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    read = json.loads(r.stdout)
    want = view["linear_rgb"].astype(np.float32).view(np.uint32).tolist()
    for name, path in linear_paths.items():
        if EXR_COMPRESSIONS[name].opencv_reads:
            assert read[path] == want, name
        else:
            assert read[path] is None, f"OpenCV reads {name} now: update the registry and the docs"


def test_an_unknown_compression_is_refused_naming_the_choices():
    with pytest.raises(ValueError, match="none"):
        encode_view("v", exr_compression="b44", **make_view(0))


_SPEC = """
name: c
render: {spp: 1RENDER}
objects:
  - {name: ball, shape: {type: sphere, radius: 0.5}}
lights:
  - {type: constant, radiance: 1}
cameras:
  cam: {model: pinhole, size: [32, 24], fov_deg: 60}
views:
  - camera: cam
    orbit: {center: [0, 0, 0], radius_m: 3, elevations_deg: [20], count: 2}
"""


def test_the_default_leaves_the_resolved_spec_and_its_hash():
    plain = parse_spec(_SPEC.replace("RENDER", ""))
    zip_ = parse_spec(_SPEC.replace("RENDER", ", exr_compression: zip"))
    none = parse_spec(_SPEC.replace("RENDER", ", exr_compression: none"))
    assert none.render.exr_compression == "none"
    assert "exr_compression" not in spec_to_dict(plain)["render"]
    assert spec_sha256(zip_) == spec_sha256(plain) != spec_sha256(none)  # part of the run's identity
    assert spec_to_dict(none)["render"]["exr_compression"] == "none"


def test_a_bad_compression_in_the_spec_names_the_field():
    from scenegen.errors import SpecError

    with pytest.raises(SpecError, match=r"exr_compression.*zstd"):
        parse_spec(_SPEC.replace("RENDER", ", exr_compression: b44"))


@pytest.mark.render
def test_a_render_with_another_compression_stores_the_same_truth(tmp_path):
    from scenegen.dataset import Dataset
    from scenegen.pipeline.run import render_spec

    runs = {}
    for name in ("zip", "zstd"):
        spec = tmp_path / f"{name}.yaml"
        spec.write_text(_SPEC.replace("RENDER", f", exr_compression: {name}"))
        render_spec(spec, tmp_path / name, progress=False)
        runs[name] = Dataset(tmp_path / name)
    a, b = runs["zip"], runs["zstd"]
    assert a.views == b.views
    for v in a.views:
        assert (b.root / f"truth/{v}.exr").read_bytes() != (a.root / f"truth/{v}.exr").read_bytes()
        assert _header_compression((b.root / f"truth/{v}.exr").read_bytes()) == OpenEXR.ZSTD_COMPRESSION
        ta, tb = a.truth(v), b.truth(v)
        for k in ta:
            assert np.array_equal(np.asarray(ta[k]), np.asarray(tb[k]), equal_nan=ta[k].dtype.kind == "f"), k
        assert np.array_equal(a.image(v), b.image(v))
