"""Scale and robustness: scene variants, Dask workers vs a serial run, kill-and-resume, verify."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset, DatasetError, load_current_manifest, verify
from scenegen.dataset.files import sha256_file
from scenegen.errors import SpecError
from scenegen.spec import load_spec, parse_spec, spec_sha256, spec_to_dict

VARIED = """
name: varied
render: {spp: 4, max_depth: 2}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: checkerboard, params: {squares_u: 6, squares_v: 6}}}
  - name: rock
    shape: {type: blob, radius: 0.3, subdivisions: 2}
    transform: {translation: [0, 0, 0.3]}
    material: {type: diffuse, color: [0.5, 0.5, 0.5]}
lights:
  - {type: point, position: [1, -1, 2], intensity: 5}
cameras:
  cam: {model: opencv, size: [16, 12], fx: 14, fy: 14, cx: 7.5, cy: 5.5, dist: [-0.1, 0.01, 0, 0]}
views:
  - camera: cam
    orbit: {center: [0, 0, 0.2], radius_m: 2.0, elevations_deg: [35], count: 1}
variation:
  seed: 11
  objects:
    rock:
      position: {min: [-0.5, -0.5, 0.3], max: [0.5, 0.5, 0.3]}
      yaw_deg: [0, 360]
      color: {min: [0.1, 0.1, 0.1], max: [0.9, 0.9, 0.9]}
      reseed: true
  lights:
    light0: {intensity_scale: [0.5, 2.0], position_jitter_m: 0.2}
  cameras:
    cam: {focal_scale: [0.9, 1.1], principal_point_px: 1.0, dist_jitter: [0.02, 0.005, 0.001, 0.001]}
  views: {translation_m: 0.05, rotation_deg: 2.0}
"""

# Several small frames, two cameras in a stereo rig: frames shard into tasks of two views.
FRAMES = """
name: frames
render: {spp: 4, max_depth: 2}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: noise, params: {size_px: 32}}}
  - name: ball
    shape: {type: sphere, radius: 0.3}
    transform: {translation: [0, 0, 0.3]}
    material: {type: plastic, color: [0.7, 0.2, 0.1]}
lights:
  - {type: point, position: [1, -1, 2], intensity: 5}
  - {type: constant, radiance: 0.1}
cameras:
  cam: {model: opencv, size: [32, 24], fx: 28, fy: 28, cx: 15.5, cy: 11.5, dist: [-0.05, 0.01, 0, 0]}
rigs:
  pair: {type: stereo, left: cam, right: cam, baseline_m: 0.1}
views:
  - rig: pair
    orbit: {center: [0, 0, 0.2], radius_m: 2.0, elevations_deg: [35], count: NFRAMES}
"""


# The same with a pinhole camera: validating a distorted camera's fold-over limit costs ~0.3 s,
# too much for 100 variants in a unit test (distortion variation is covered by the rendered test).
VARIED_PINHOLE = (VARIED.replace("model: opencv", "model: pinhole").replace(", dist: [-0.1, 0.01, 0, 0]", "")
                  .replace(", dist_jitter: [0.02, 0.005, 0.001, 0.001]", ""))


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def _hashes(root: Path) -> dict:
    return {p.relative_to(root).as_posix(): sha256_file(p) for p in sorted(root.rglob("*")) if p.is_file()}


# --- variants -----------------------------------------------------------------------------------
class TestVariationSpec:
    @pytest.mark.parametrize("snippet, field, message", [
        ("objects: {rok: {yaw_deg: [0, 1]}}", "variation.objects.rok", "undefined object 'rok'"),
        ("objects: {floor: {color: {min: [0, 0, 0], max: [1, 1, 1]}}}", "variation.objects.floor.color",
         "with a texture"),
        ("objects: {rock: {yaw_deg: [10, 0]}}", "variation.objects.rock.yaw_deg", "min <= max"),
        ("objects: {rock: {color: {min: [0, 0, 0], max: [1, 2, 1]}}}", "variation.objects.rock.color.max", "<= 1"),
        ("cameras: {cam: {dist_jitter: [0.1, 0.1]}}", "variation.cameras.cam.dist_jitter", "4 numbers"),
        ("cameras: {cam: {focal_scale: [0, 1]}}", "variation.cameras.cam.focal_scale", "> 0"),
        ("lights: {light0: {intensity_scale: [-1, 1]}}", "variation.lights.light0.intensity_scale", ">= 0"),
        ("views: {rotation_deg: 200}", "variation.views.rotation_deg", "<= 180"),
        ("colour: 1", "variation.colour", "unknown key 'colour'"),
    ])
    def test_bad_ranges_name_file_line_field(self, snippet, field, message):
        head = VARIED.split("variation:")[0]
        with pytest.raises(SpecError) as e:
            parse_spec(head + "variation:\n  " + snippet + "\n", file="v.yaml")
        text = str(e.value)
        assert text.startswith("v.yaml:") and field in text and message in text, text

    def test_cli_bad_variation_exits_2_without_traceback(self, tmp_path, capsys):
        spec = _write(tmp_path, "bad.yaml", VARIED.replace("rock: {", "rok: {").replace("    rock:\n", "    rok:\n"))
        assert main(["render", str(spec), "-o", str(tmp_path / "out"), "--variants", "2", "-q"]) == 2
        err = capsys.readouterr().err
        assert "undefined object 'rok'" in err and "Traceback" not in err

    def test_variants_need_a_variation_section(self, tmp_path, capsys):
        spec = _write(tmp_path, "plain.yaml", VARIED.split("variation:")[0])
        assert main(["render", str(spec), "-o", str(tmp_path / "out"), "--variants", "2", "-q"]) == 2
        assert "needs a 'variation:' section" in capsys.readouterr().err


@pytest.mark.parametrize("args, message", [
    (["--variants", "0"], "--variants must be at least 1"),
    (["--workers", "0"], "--workers must be at least 1"),
    (["--workers", "1", "--scheduler", "tcp://127.0.0.1:1"], "not allowed with argument --workers"),
])
def test_cli_bad_scale_options_exit_2(tmp_path, capsys, args, message):
    spec = _write(tmp_path, "varied.yaml", VARIED)
    try:
        code = main(["render", str(spec), "-o", str(tmp_path / "out"), "-q", *args])
    except SystemExit as e:  # argparse's own errors
        code = e.code
    assert code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_100_variants_are_valid_distinct_and_reproducible(tmp_path):
    from scenegen.spec.variants import derive_variant

    spec = load_spec(_write(tmp_path, "varied.yaml", VARIED_PINHOLE))
    base_hash = spec_sha256(spec)
    variants = [derive_variant(spec, i) for i in range(100)]  # each is checked (cameras, views)
    hashes = [spec_sha256(v) for v in variants]
    assert len(set(hashes)) == 100 and base_hash not in hashes
    assert hashes == [spec_sha256(derive_variant(spec, i)) for i in range(100)]  # same seed + index
    assert spec_sha256(spec) == base_hash  # the spec itself is untouched
    assert spec_sha256(derive_variant(spec, 5, seed=12)) != hashes[5]  # another seed, another scene
    for i, v in enumerate(variants):  # drawn values lie in their ranges and are recorded
        d = spec_to_dict(v)["variant"]
        assert d["index"] == i and d["seed"] == 11
        rock = d["objects"]["rock"]
        assert -0.5 <= rock["position"][0] <= 0.5 and rock["position"][2] == 0.3
        assert 0 <= rock["yaw_deg"] <= 360 and all(0.1 <= c <= 0.9 for c in rock["color"])
        assert 0.5 <= d["lights"]["light0"]["intensity_scale"] <= 2.0
        cam = v.cameras["cam"]
        assert 14 * 0.9 <= cam.fx <= 14 * 1.1 and cam.fx == cam.fy and abs(cam.cx - 7.5) <= 1.0
        assert len(d["views"]) == 1 and d["views"][0]["rotation_deg"] <= 2.0
        obj = {o.name: o for o in v.objects}["rock"]
        assert np.allclose(obj.transform.world_from_object.t, rock["position"])
        assert obj.material.color == tuple(rock["color"]) and obj.geometry.seed == rock["blob_seed"]


@pytest.mark.render
def test_rendered_variants_differ_and_reproduce(tmp_path):
    spec = _write(tmp_path, "varied.yaml", VARIED)
    out_a, out_b = tmp_path / "a", tmp_path / "b"
    assert main(["render", str(spec), "-o", str(out_a), "--variants", "3", "-q"]) == 0
    images = [sha256_file(out_a / f"variant_{i:04d}" / "images" / "cam_0000.png") for i in range(3)]
    truths = [sha256_file(out_a / f"variant_{i:04d}" / "truth" / "cam_0000.exr") for i in range(3)]
    assert len(set(images)) == 3 and len(set(truths)) == 3
    for i in range(3):
        d = Dataset(out_a / f"variant_{i:04d}")
        assert d.spec["variant"]["index"] == i and verify(d.root).ok
        cam, _ = d.camera("cam_0000")  # cameras.json holds the drawn intrinsics and distortion
        drawn = d.spec["variant"]["cameras"]["cam"]
        assert cam.fx == drawn["fx"] and list(cam.dist[:4]) == drawn["dist"] and not any(cam.dist[4:])
        assert abs(cam.dist[0] + 0.1) <= 0.02 and cam.dist[0] != -0.1
    # a second run of the first two variants: the same bytes, file by file
    assert main(["render", str(spec), "-o", str(out_b), "--variants", "2", "-q"]) == 0
    for i in range(2):
        name = f"variant_{i:04d}"
        assert _hashes(out_b / name) == _hashes(out_a / name)


# --- Dask workers vs a serial run ---------------------------------------------------------------
@pytest.mark.render
def test_dask_workers_match_serial_run_and_load_each_scene_once(tmp_path):
    from scenegen.pipeline.distributed import open_client, worker_stats
    from scenegen.pipeline.run import render_spec

    spec = _write(tmp_path, "frames.yaml", FRAMES.replace("NFRAMES", "4"))
    serial, dist = tmp_path / "serial", tmp_path / "dist"
    render_spec(spec, serial, progress=False)
    with open_client(workers=2) as client:
        s = render_spec(spec, dist, progress=False, dask_client=client)
        stats = list(client.run(worker_stats).values())
    assert s.views_rendered == 8
    assert (dist / "manifest.json").read_bytes() == (serial / "manifest.json").read_bytes()
    assert _hashes(dist) == _hashes(serial)
    assert sum(st["views_rendered"] for st in stats) == 8
    assert all(st["scene_loads"] <= 1 for st in stats)  # kept, not reloaded per frame
    assert all(st["pid"] != os.getpid() for st in stats)  # rendered in worker processes
    # each local worker's Dr.Jit pool is its share of the cores (the serial run's is all of them)
    assert all(st["render_threads"] == max(1, os.cpu_count() // 2) for st in stats if st["views_rendered"])


# --- kill and resume ----------------------------------------------------------------------------
def _complete_views(out: Path) -> int:
    try:
        m = load_current_manifest(out)  # manifest.json plus the running writer's journal
    except (OSError, ValueError, DatasetError):
        return 0
    return sum(e["status"] == "complete" for e in m["views"].values())


def _run_and_kill(spec: Path, out: Path, *, resume: bool, after_s: float | None = None,
                  after_views: int | None = None, extra=()) -> int:
    """Start `scenegen render`, SIGKILL it at the given point; returns views complete then.
    Its child processes (Dask workers) must end with it."""
    import psutil

    cmd = [sys.executable, "-m", "scenegen.cli", "render", str(spec), "-o", str(out), "-q", *extra]
    proc = subprocess.Popen(cmd + (["--resume"] if resume else []), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    t0 = time.monotonic()
    children = []
    try:
        while proc.poll() is None and time.monotonic() - t0 < 120:
            if after_s is not None and time.monotonic() - t0 >= after_s:
                break
            if after_views is not None and _complete_views(out) >= after_views:
                break
            time.sleep(0.005)
        assert proc.poll() is None, "the run finished before it could be killed"
        children = psutil.Process(proc.pid).children(recursive=True)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    assert proc.returncode == -signal.SIGKILL
    _, alive = psutil.wait_procs(children, timeout=30)
    assert not alive, f"worker processes outlived the killed run: {alive}"
    return _complete_views(out)


@pytest.mark.render
def test_sigkill_at_several_points_then_resume_gives_the_uninterrupted_dataset(tmp_path):
    from scenegen.pipeline.run import render_spec

    spec = _write(tmp_path, "frames.yaml", FRAMES.replace("NFRAMES", "10"))
    ref, out = tmp_path / "ref", tmp_path / "out"
    render_spec(spec, ref, progress=False)
    done = [_run_and_kill(spec, out, resume=False, after_s=0.3)]  # while starting up
    done.append(_run_and_kill(spec, out, resume=True, after_views=1))
    done.append(_run_and_kill(spec, out, resume=True, after_views=done[-1] + 3))
    # a distributed run resumes a serial one, is killed in turn, and a serial run finishes it
    done.append(_run_and_kill(spec, out, resume=True, after_views=done[-1] + 2, extra=("--workers", "2")))
    assert done[0] == 0 and 1 <= done[1] < done[2] < done[3] < 20
    assert not verify(out).ok  # interrupted: incomplete views (and maybe unrecorded files)
    assert main(["render", str(spec), "-o", str(out), "-q", "--resume"]) == 0
    assert (out / "manifest.json").read_bytes() == (ref / "manifest.json").read_bytes()
    assert _hashes(out) == _hashes(ref)
    assert verify(out).ok


# --- verify on a rendered dataset ---------------------------------------------------------------
_KINDS = {  # kind of file -> how to recognise its relative path
    "manifest": lambda r: r == "manifest.json",
    "cameras": lambda r: r == "cameras.json",
    "mesh": lambda r: r.startswith("scene/meshes/"),
    "image": lambda r: r.startswith("images/") and r.endswith(".png"),
    "linear": lambda r: r.endswith("_linear.exr"),
    "truth": lambda r: r.startswith("truth/") and r.endswith(".exr") and not r.endswith("_ids.exr"),
    "ids": lambda r: r.endswith("_ids.exr"),
    "valid": lambda r: r.endswith("_valid.png"),
}


@pytest.mark.render
def test_verify_cli_names_any_file_with_a_flipped_byte(tmp_path, capsys):
    from scenegen.pipeline.run import render_spec

    spec = _write(tmp_path, "frames.yaml", FRAMES.replace("NFRAMES", "1"))
    out = tmp_path / "out"
    render_spec(spec, out, progress=False)
    assert main(["verify", str(out)]) == 0
    capsys.readouterr()
    files = ["manifest.json"] + sorted(Dataset(out).manifest["files"])
    for kind, match in _KINDS.items():
        rel = next(r for r in files if match(r))
        p = out / rel
        data = bytearray(p.read_bytes())
        k = len(data) // 2
        data[k] ^= 0x01
        p.write_bytes(bytes(data))
        assert main(["verify", str(out)]) == 1, kind
        text = capsys.readouterr().out
        assert "FAILED" in text and f"corrupted (1):\n  {rel}" in text, (kind, text)
        data[k] ^= 0x01
        p.write_bytes(bytes(data))
    assert main(["verify", str(out)]) == 0


# --- batched recording (the Dask client) ----------------------------------------------------------
def test_record_views_batches_into_the_same_manifest_and_is_all_or_nothing(tmp_path):
    from scenegen import dataset as ds

    def writer(name):
        w = ds.DatasetWriter(tmp_path / name, spec_sha256="a" * 64, seed=0, variant="v", versions={})
        w.write_cameras({f"v{i}": {"camera": {}, "cam_from_world": {}} for i in range(4)}, {})
        return w

    hashes = {f"v{i}": {rel: f"{i * 5 + k:064x}" for k, rel in enumerate(ds.view_paths(f"v{i}").values())}
              for i in range(4)}
    one, batched = writer("one"), writer("batched")
    for v, h in hashes.items():
        one.record_view(v, h)
    batched.record_views({"v0": hashes["v0"]})
    bad = {"v1": hashes["v1"], "v2": {**hashes["v2"], "images/v2.png": "not a hash"}}
    with pytest.raises(ValueError, match="images/v2.png"):
        batched.record_views(bad)
    assert batched.completed_views == ("v0",)  # v1 was not recorded either
    batched.record_views({v: hashes[v] for v in ("v1", "v2", "v3")})
    assert ds.load_current_manifest(tmp_path / "batched") == ds.load_current_manifest(tmp_path / "one")
    one.close()
    batched.close()
    assert (tmp_path / "batched" / "manifest.json").read_bytes() == (tmp_path / "one" / "manifest.json").read_bytes()
    assert not (tmp_path / "one" / "manifest.journal").exists()
