"""scenegen.dataset: layout, determinism, resume after a crash, reader round trip, verify."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from scenegen import dataset as ds
from scenegen.dataset import codecs as sio, files, writer as writer_module
from scenegen.geometry.pose import Rigid3, look_at

SPEC_SHA = "ab" * 32
VERSIONS = {"python": "3.x", "numpy": "2.x", "mitsuba": "3.9.1", "drjit": "1.5.0", "opencv": "4.x"}
H, W = 6, 8
VIEWS = ["cam0_000", "cam0_001", "cam1_000", "v10", "v2"]  # "v10" before "v2": order kept, not sorted
CAMERA_DICT = {"model": "pinhole", "width": W, "height": H, "fx": 10.0, "fy": 11.0, "cx": 3.5,
               "cy": 2.5, "skew": 0.0, "dist": []}


def make_view(seed: int):
    """A view whose truth obeys the miss convention: a random hit mask, misses as documented."""
    rng = np.random.default_rng(seed)
    valid = rng.random((H, W)) < 0.7
    f32 = lambda *s: rng.uniform(-5, 5, (H, W) + s).astype(np.float32)  # noqa: E731
    truth = {"depth_z": np.abs(f32()) + 0.1, "range": np.abs(f32()) + 0.2, "points_world": f32(3),
             "points_cam": f32(3), "normals_world": f32(3), "normals_cam": f32(3), "uv": f32(2),
             "object_id": rng.integers(1, 5, (H, W)).astype(np.uint32),
             "instance_id": rng.integers(1, 2**32, (H, W), dtype=np.uint32), "valid": valid}
    for k in ("depth_z", "range"):
        truth[k][~valid] = np.inf
    for k in ("points_world", "points_cam", "normals_world", "normals_cam", "uv"):
        truth[k][~valid] = np.nan
    for k in ("object_id", "instance_id"):
        truth[k][~valid] = 0
    image = rng.integers(0, 65536, (H, W, 3), dtype=np.uint16) if seed % 2 else \
        rng.integers(0, 256, (H, W, 3), dtype=np.uint8)
    return {"image": image, "linear_rgb": f32(3), "truth": truth}


def view_cameras():
    return {v: ds.ViewCamera(camera=CAMERA_DICT,
                             cam_from_world=look_at((i + 1.0, 2.0, 3.0), (0, 0, 0)).inverse(),
                             camera_name=v.split("_")[0], rig="stereo" if v.startswith("cam") else None,
                             rig_member=v.split("_")[0] if v.startswith("cam") else None,
                             frame_index=i)
            for i, v in enumerate(VIEWS)}


SPEC = {"objects": [{"name": "box"}], "render": {"spp": 16, "seed": 7}}


def new_writer(out, resume=False, **kw):
    args = dict(spec_sha256=SPEC_SHA, seed=7, variant="llvm_ad_rgb", versions=VERSIONS)
    args.update(kw)
    return ds.DatasetWriter(out, resume=resume, **args)


def write_dataset(out, views=VIEWS, writer=None):
    w = writer or new_writer(out)
    w.write_cameras(view_cameras(), SPEC)
    w.write_mesh("box", trimesh.creation.box(extents=(1, 2, 3)))
    for v in views:
        if not w.is_complete(v):
            w.write_view(v, **make_view(VIEWS.index(v)))
    w.close()  # compacts the journal into manifest.json
    return w


def bits_equal(a, b):
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def all_bytes(root: Path) -> dict:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in root.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def complete(tmp_path_factory):
    out = tmp_path_factory.mktemp("complete") / "out"
    write_dataset(out)
    return out


class TestLayoutAndReader:
    def test_file_layout(self, complete):
        files = set(all_bytes(complete))
        expected = {"manifest.json", "cameras.json", "scene/meshes/box.ply"}
        for v in VIEWS:
            expected |= {f"images/{v}.png", f"images/{v}_linear.exr", f"truth/{v}.exr",
                         f"truth/{v}_ids.exr", f"truth/{v}_valid.png"}
        assert files == expected

    def test_manifest_content(self, complete):
        m = sio.read_json(complete / "manifest.json")
        assert (m["format"], m["format_version"], m["spec_sha256"], m["seed"], m["variant"]) == \
            ("scenegen-dataset", 1, SPEC_SHA, 7, "llvm_ad_rgb")
        assert m["versions"] == VERSIONS
        assert set(m["views"]) == set(VIEWS)
        assert all(e["status"] == "complete" for e in m["views"].values())
        on_disk = set(all_bytes(complete)) - {"manifest.json"}
        assert set(m["files"]) == on_disk
        assert all(m["files"][r] == files.sha256_file(complete / r) for r in on_disk)

    def test_reader_round_trip_bit_exact(self, complete):
        d = ds.Dataset(complete)
        assert d.views == tuple(VIEWS)
        for i, v in enumerate(VIEWS):
            src = make_view(i)
            assert bits_equal(d.image(v), src["image"])
            assert bits_equal(d.linear_image(v), src["linear_rgb"])
            t = d.truth(v)
            assert set(t) == set(ds.TRUTH_KEYS)
            for k in ds.TRUTH_KEYS:
                assert bits_equal(t[k], src["truth"][k]), (v, k)
            assert bits_equal(d.object_ids(v), src["truth"]["object_id"])  # the ids file alone
            assert bits_equal(d.depth_z(v), src["truth"]["depth_z"])
            assert d.image_path(v) == complete / f"images/{v}.png"

    def test_camera_and_info(self, complete):
        d = ds.Dataset(complete)
        cam, cam_from_world = d.camera("cam1_000")
        assert (cam.fx, cam.fy, cam.cx, cam.width, cam.height) == (10.0, 11.0, 3.5, W, H)
        expected = view_cameras()["cam1_000"].cam_from_world
        assert np.array_equal(cam_from_world.R, expected.R) and np.array_equal(cam_from_world.t, expected.t)
        info = d.view_info("cam1_000")
        assert (info["camera_name"], info["rig"], info["rig_member"], info["frame_index"]) == \
            ("cam1", "stereo", "cam1", 2)
        assert d.spec == SPEC

    def test_mesh(self, complete):
        d = ds.Dataset(complete)
        assert d.mesh_names == ("box",)
        m = d.mesh("box")
        box = trimesh.creation.box(extents=(1, 2, 3))
        assert np.array_equal(m.vertices, box.vertices.astype(np.float32))
        assert np.array_equal(m.faces, box.faces)

    def test_reader_needs_no_mitsuba(self, complete):
        code = ("import sys; from scenegen.dataset import Dataset; d = Dataset(sys.argv[1]); "
                "[(d.truth(v), d.image(v), d.camera(v)) for v in d.views]; "
                "bad = [m for m in ('mitsuba', 'drjit') if m in sys.modules]; assert not bad, bad")
        r = subprocess.run([sys.executable, "-c", code, str(complete)], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr

    def test_unknown_view(self, complete):
        with pytest.raises(KeyError, match="nope"):
            ds.Dataset(complete).truth("nope")


class TestDeterminism:
    def test_identical_runs_identical_bytes(self, tmp_path, complete):
        write_dataset(tmp_path / "b")
        assert all_bytes(tmp_path / "b") == all_bytes(complete)

    def test_view_order_does_not_change_manifest(self, tmp_path, complete):
        write_dataset(tmp_path / "b", views=list(reversed(VIEWS)))
        assert (tmp_path / "b" / "manifest.json").read_bytes() == (complete / "manifest.json").read_bytes()

    def test_worker_path_gives_same_manifest(self, tmp_path, complete):
        """write_view_files (in a worker) + record_view (in the owner) == write_view."""
        out = tmp_path / "b"
        w = new_writer(out)
        w.write_cameras(view_cameras(), SPEC)
        w.write_mesh("box", trimesh.creation.box(extents=(1, 2, 3)))
        for i, v in enumerate(VIEWS):
            w.record_view(v, ds.write_view_files(out, v, **make_view(i)))
        w.close()  # compacts the journal and releases the folder's lock
        assert all_bytes(out) == all_bytes(complete)


class TestResume:
    def test_resume_after_kill_equals_uninterrupted(self, tmp_path, complete, monkeypatch):
        out = tmp_path / "b"
        write_dataset(out, views=VIEWS[:2])
        # a "kill" in the middle of the third view: two of its files in place, then death
        real, calls = os.replace, []

        def dying(src, dst):
            if Path(dst).name != "manifest.json":
                calls.append(dst)
            if len(calls) == 3:
                raise KeyboardInterrupt("SIGKILL stand-in")
            real(src, dst)

        monkeypatch.setattr(os, "replace", dying)
        with pytest.raises(KeyboardInterrupt):
            new_writer(out, resume=True).write_view(VIEWS[2], **make_view(2))
        monkeypatch.setattr(os, "replace", real)
        (out / "truth" / f".x.exr.123{files.TEMP_SUFFIX}").write_bytes(b"half")  # a killed temp file

        m = sio.read_json(out / "manifest.json")
        assert [v for v, e in m["views"].items() if e["status"] == "complete"] == VIEWS[:2]
        rep = ds.verify(out)
        assert not rep.ok and rep.incomplete_views == tuple(sorted(VIEWS[2:]))
        assert rep.missing == rep.corrupted == ()
        assert len(rep.unexpected) == 3  # the killed view's two files + the temp file

        w = new_writer(out, resume=True)
        assert [w.is_complete(v) for v in VIEWS] == [True, True, False, False, False]
        written = []
        orig = w.write_view
        w.write_view = lambda v, **kw: (written.append(v), orig(v, **kw))
        write_dataset(out, writer=w).close()
        assert written == VIEWS[2:]
        assert all_bytes(out) == all_bytes(complete)
        assert ds.verify(out).ok

    @pytest.mark.parametrize("field,value", [("seed", 8), ("variant", "scalar_rgb"),
                                             ("spec_sha256", "cd" * 32),
                                             ("versions", {**VERSIONS, "mitsuba": "3.9.2"})])
    def test_mismatch_refused(self, tmp_path, field, value):
        write_dataset(tmp_path / "b", views=VIEWS[:1])
        before = all_bytes(tmp_path / "b")
        with pytest.raises(ds.DatasetMismatchError, match=field):
            new_writer(tmp_path / "b", resume=True, **{field: value})
        assert all_bytes(tmp_path / "b") == before

    def test_non_empty_dir_without_resume_refused(self, tmp_path):
        write_dataset(tmp_path / "b", views=VIEWS[:1])
        with pytest.raises(ds.DatasetError, match="render again with --resume"):
            new_writer(tmp_path / "b")
        (tmp_path / "c").mkdir()
        (tmp_path / "c" / "notes.txt").write_text("mine")
        with pytest.raises(ds.DatasetError, match="no manifest"):
            new_writer(tmp_path / "c", resume=True)

    def test_rewriting_complete_view_with_other_content_refused(self, tmp_path):
        out = tmp_path / "b"
        w = write_dataset(out, views=VIEWS[:1])
        before = all_bytes(out)
        w.write_view(VIEWS[0], **make_view(0))  # same content: fine
        with pytest.raises(ds.DatasetMismatchError, match="not deterministic"):
            w.write_view(VIEWS[0], **make_view(1))
        assert all_bytes(out) == before


class TestVerify:
    KINDS = ["manifest.json", "cameras.json", "scene/meshes/box.ply", "images/v2.png",
             "images/v2_linear.exr", "truth/v2.exr", "truth/v2_ids.exr", "truth/v2_valid.png"]

    def test_clean(self, complete):
        rep = ds.verify(complete)
        assert rep.ok, rep.summary()
        assert rep.files_checked == 2 + 5 * len(VIEWS)

    @pytest.mark.parametrize("rel", KINDS)
    @pytest.mark.parametrize("where", [0.0, 0.5, 1.0])
    def test_flipped_byte_names_exactly_that_file(self, tmp_path, complete, rel, where):
        out = tmp_path / "b"
        for r, data in all_bytes(complete).items():
            files.atomic_write_bytes(out / r, data)
        data = bytearray((out / rel).read_bytes())
        i = min(int(where * len(data)), len(data) - 1)
        data[i] ^= 0x01
        (out / rel).write_bytes(bytes(data))
        rep = ds.verify(out)
        assert not rep.ok
        assert rep.corrupted == (rel,)
        assert rep.missing == rep.unexpected == rep.incomplete_views == ()

    @pytest.mark.parametrize("rel", KINDS[1:])
    def test_deleted_file_is_missing(self, tmp_path, complete, rel):
        out = tmp_path / "b"
        for r, data in all_bytes(complete).items():
            files.atomic_write_bytes(out / r, data)
        (out / rel).unlink()
        rep = ds.verify(out)
        assert (rep.ok, rep.missing, rep.corrupted, rep.unexpected) == (False, (rel,), (), ())

    def test_unexpected_and_no_manifest(self, tmp_path, complete):
        out = tmp_path / "b"
        for r, data in all_bytes(complete).items():
            files.atomic_write_bytes(out / r, data)
        (out / "images" / "extra.png").write_bytes(b"x")
        assert ds.verify(out).unexpected == ("images/extra.png",)
        (out / "manifest.json").unlink()
        rep = ds.verify(out)
        assert not rep.ok and rep.missing == ("manifest.json",)


class TestValidation:
    def test_float64_truth_stored_as_float32(self, tmp_path):
        """The truth pass derives in float64; the format stores float32 (rounded to nearest)."""
        v = make_view(0)
        p64 = v["truth"]["points_world"].astype(np.float64) + 1e-9  # not representable in float32
        v["truth"]["points_world"] = p64
        w = new_writer(tmp_path / "b")
        w.write_view("a", **v)
        back = ds.Dataset(tmp_path / "b").truth("a")["points_world"]
        assert bits_equal(back, p64.astype(np.float32))

    def test_truth_must_be_float(self, tmp_path):
        v = make_view(0)
        v["truth"]["depth_z"] = np.zeros((H, W), np.int32)
        with pytest.raises(TypeError, match="depth_z.*float"):
            new_writer(tmp_path / "b").write_view("a", **v)

    @pytest.mark.parametrize("key,value,msg", [
        ("depth_z", 1.0, r"\+inf where valid is False"),
        ("points_cam", 0.0, "NaN where valid is False"),
        ("object_id", 3, "0 where valid is False"),
    ])
    def test_miss_convention_enforced(self, tmp_path, key, value, msg):
        v = make_view(0)
        v["truth"][key][~v["truth"]["valid"]] = value
        with pytest.raises(ValueError, match=msg):
            new_writer(tmp_path / "b").write_view("a", **v)

    def test_hit_must_be_finite(self):
        v = make_view(0)
        v["truth"]["range"][v["truth"]["valid"]] = np.inf
        with pytest.raises(ValueError, match="finite where valid"):
            ds.check_truth(v["truth"])

    def test_missing_truth_key(self):
        v = make_view(0)
        del v["truth"]["uv"]
        with pytest.raises(ValueError, match="missing \\['uv'\\]"):
            ds.check_truth(v["truth"])

    @pytest.mark.parametrize("name", ["a_ids", "b_valid", "c_linear", "../x", ".hidden", "a b", ""])
    def test_bad_view_names(self, tmp_path, name):
        with pytest.raises(ValueError, match="view name"):
            new_writer(tmp_path / "b").write_view(name, **make_view(0))

    def test_failed_view_leaves_dataset_unchanged(self, tmp_path):
        out = tmp_path / "b"
        w = write_dataset(out, views=VIEWS[:1])
        before = all_bytes(out)
        v = make_view(1)
        v["linear_rgb"] = v["linear_rgb"][:-1]
        with pytest.raises(ValueError, match="linear_rgb"):
            w.write_view(VIEWS[1], **v)
        assert all_bytes(out) == before

    def test_cameras_json_is_plain(self, complete):
        cams = json.loads((complete / "cameras.json").read_text())
        assert cams["view_order"] == VIEWS
        e = cams["views"]["cam0_001"]
        assert set(e) == {"camera", "cam_from_world", "camera_name", "rig", "rig_member", "frame_index"}
        assert Rigid3.from_dict(e["cam_from_world"]).allclose(view_cameras()["cam0_001"].cam_from_world, 0)


_SLOW_WRITER = r"""
import sys, time
sys.path.insert(0, sys.argv[2])
from scenegen.dataset import files
import test_dataset as t

real = files.write_payload

def slow(f, data):  # be killable between the two halves of every file
    f.write(data[: len(data) // 2]); f.flush(); time.sleep(0.01); real(f, data[len(data) // 2:])

files.write_payload = slow
t.write_dataset(t.Path(sys.argv[1]))
print("finished")
"""


def test_sigkill_and_resume_equals_uninterrupted(tmp_path, complete):
    """A real SIGKILL in the middle of a run, then resume=True: the same bytes as a clean run."""
    import time

    out = tmp_path / "b"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_WRITER, str(out), str(Path(__file__).parent)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            views = ds.load_current_manifest(out)["views"]  # manifest.json + the run's journal
        except (ds.DatasetError, FileNotFoundError, ValueError, KeyError):
            views = {}
        if sum(e["status"] == "complete" for e in views.values()) >= 2:
            break
        time.sleep(0.005)
    time.sleep(0.013)  # land somewhere inside the next view's files
    proc.kill()
    stdout, stderr = proc.communicate()
    assert b"finished" not in stdout, "the writer finished before it could be killed"
    rep = ds.verify(out)
    assert not rep.ok and rep.missing == rep.corrupted == () and rep.incomplete_views
    write_dataset(out, writer=new_writer(out, resume=True))
    assert all_bytes(out) == all_bytes(complete)
    assert ds.verify(out).ok
