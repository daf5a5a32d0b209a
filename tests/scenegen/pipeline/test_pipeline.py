"""The main job end to end: spec -> dataset, determinism, CLI behaviour on good and bad input."""
import json
import subprocess
import sys

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset, verify

TINY = """
name: tiny
render: {spp: 4, max_depth: 3, sampler: ldsampler, bit_depth: 16}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: checkerboard, params: {squares_u: 6, squares_v: 6}}}
  - name: rock
    shape: {type: blob, radius: 0.3, subdivisions: 3}
    transform: {translation: [0, 0, 0.3]}
    material: {type: plastic, texture: {type: noise, params: {size_px: 64}}}
lights:
  - {type: point, position: [1, -1, 2], intensity: 5}
  - {type: constant, radiance: 0.2}
cameras:
  cam: {model: opencv, size: [96, 72], fx: 80, fy: 81, cx: 47.2, cy: 35.9, dist: [-0.1, 0.01, 0, 0]}
views:
  - camera: cam
    orbit: {center: [0, 0, 0.2], radius_m: 2.0, elevations_deg: [35], count: 3}
"""


@pytest.fixture(scope="module")
def tiny_spec(tmp_path_factory):
    p = tmp_path_factory.mktemp("spec") / "tiny.yaml"
    p.write_text(TINY)
    return p


@pytest.fixture(scope="module")
def rendered(tiny_spec, tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "a"
    assert main(["render", str(tiny_spec), "-o", str(out), "-q"]) == 0
    return out


@pytest.mark.render
def test_dataset_contents(rendered):
    d = Dataset(rendered)
    assert d.views == ("cam_0000", "cam_0001", "cam_0002")
    img = d.image("cam_0001")
    assert img.dtype == np.uint16 and img.shape == (72, 96, 3) and img.max() > 1000
    t = d.truth("cam_0001")
    cam, pose = d.camera("cam_0001")
    v = t["valid"]
    assert v.mean() > 0.5
    uv = cam.project(t["points_cam"][v].astype(np.float64))
    grid = np.stack(np.meshgrid(np.arange(96), np.arange(72)), -1)[v]
    assert np.abs(uv - grid).max() < 1e-3
    assert verify(rendered).ok


@pytest.mark.render
def test_same_spec_twice_gives_identical_hashes(tiny_spec, rendered, tmp_path):
    out = tmp_path / "b"
    assert main(["render", str(tiny_spec), "-o", str(out), "-q"]) == 0
    a = json.loads((rendered / "manifest.json").read_text())
    b = json.loads((out / "manifest.json").read_text())
    assert a["files"] == b["files"]
    assert (rendered / "manifest.json").read_bytes() == (out / "manifest.json").read_bytes()


@pytest.mark.render
def test_frames_and_resume(tiny_spec, rendered, tmp_path):
    out = tmp_path / "c"
    assert main(["render", str(tiny_spec), "-o", str(out), "-q", "--frames", "1"]) == 0
    assert Dataset(out).views == ("cam_0001",)
    assert main(["render", str(tiny_spec), "-o", str(out), "-q"]) == 2  # not empty, no --resume
    assert main(["render", str(tiny_spec), "-o", str(out), "-q", "--resume", "--frames", "0-2"]) == 0
    a = json.loads((rendered / "manifest.json").read_text())["files"]
    c = json.loads((out / "manifest.json").read_text())["files"]
    assert a == c  # a resumed, piecewise run equals the one-shot run


@pytest.mark.render
def test_seed_changes_noise_only(tiny_spec, rendered, tmp_path):
    out = tmp_path / "d"
    assert main(["render", str(tiny_spec), "-o", str(out), "-q", "--seed", "5", "--frames", "0"]) == 0
    a, b = Dataset(rendered), Dataset(out)
    assert not np.array_equal(a.linear_image("cam_0000"), b.linear_image("cam_0000"))
    np.testing.assert_array_equal(a.truth("cam_0000")["depth_z"], b.truth("cam_0000")["depth_z"])


@pytest.mark.parametrize("argv, fragment", [
    (["render", "missing.yaml", "-o", "x"], "missing.yaml"),
    (["validate", "missing.yaml"], "missing.yaml"),
    (["render", "SPEC", "-o", "OUT", "--frames", "7"], "--frames"),
    (["render", "SPEC", "-o", "OUT", "--frames", "a-b"], "--frames"),
    (["render", "SPEC", "-o", "OUT", "--variant", "nope"], "invalid choice"),
    (["info", "does/not/exist"], "does/not/exist"),
])
def test_cli_bad_input_exits_2(argv, fragment, tiny_spec, tmp_path, capsys):
    argv = [str(tiny_spec) if a == "SPEC" else str(tmp_path / "o") if a == "OUT" else a for a in argv]
    with pytest.raises(SystemExit) if "--variant" in argv else _nullctx() as exc:
        code = main(argv)
    code = exc.value.code if "--variant" in argv else code
    assert code == 2
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err


class _nullctx:
    def __enter__(self):
        return self

    def __exit__(self, *a):
        return False


def test_bad_spec_exits_2_naming_file_and_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(TINY.replace("radius_m: 2.0", "radius_m: -2.0"))
    r = subprocess.run([sys.executable, "-m", "scenegen.cli", "validate", str(bad)], capture_output=True, text=True)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    line = next(i + 1 for i, l in enumerate(TINY.splitlines()) if "radius_m" in l)
    assert f"bad.yaml:{line}" in r.stderr and "radius_m" in r.stderr


def test_validate_ok(tiny_spec, capsys):
    assert main(["validate", str(tiny_spec)]) == 0
    assert "3 views" in capsys.readouterr().out


def test_scalar_fallback_gives_the_same_truth(tmp_path):
    """The scalar_rgb fallback (no libLLVM) casts the same truth as the LLVM variant."""
    spec = tmp_path / "small.yaml"
    spec.write_text(TINY.replace("size: [96, 72], fx: 80, fy: 81, cx: 47.2, cy: 35.9",
                                 "size: [32, 24], fx: 27, fy: 27, cx: 15.7, cy: 11.9").replace("count: 3", "count: 1"))
    outs = {}
    for variant in ("scalar_rgb", "llvm_ad_rgb"):
        out = tmp_path / variant
        r = subprocess.run([sys.executable, "-m", "scenegen.cli", "render", str(spec), "-o", str(out), "-q",
                            "--variant", variant], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        outs[variant] = Dataset(out)
    a, b = (outs[v].truth("cam_0000") for v in ("scalar_rgb", "llvm_ad_rgb"))
    assert a["valid"].mean() > 0.5
    np.testing.assert_array_equal(a["valid"], b["valid"])
    np.testing.assert_array_equal(a["object_id"], b["object_id"])
    v = a["valid"]
    # float32 ray casting in both; the derivations differ only in float32 rounding order
    np.testing.assert_allclose(a["depth_z"][v], b["depth_z"][v], rtol=1e-6)
    np.testing.assert_allclose(a["normals_world"][v], b["normals_world"][v], atol=1e-5)
    assert outs["scalar_rgb"].manifest["variant"] == "scalar_rgb"
