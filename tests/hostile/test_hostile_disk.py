"""A full disk and a read-only folder (issue 18): one line naming the file and what to do, exit 2,
nothing already written lost, and after a full disk ``--resume`` on a larger disk completes the
dataset to the same bytes. The small disks are tmpfs mounts: these tests need root (CI runs as
root) and fail, not skip, without it."""
from __future__ import annotations

import errno
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import run_cli  # noqa: E402

sys.path.insert(0, str(Path(__file__).parents[1] / "scenegen" / "dataset"))
from test_dataset import all_bytes, new_writer, write_dataset  # noqa: E402

from scenegen import dataset as ds  # noqa: E402


@pytest.fixture()
def small_disk(tmp_path):
    """``mount(size, ro=False)`` -> a fresh tmpfs of ``size`` bytes under tmp_path (unmounted after)."""
    mounted = []

    def mount(size: int, ro: bool = False) -> Path:
        d = tmp_path / f"disk{len(mounted)}"
        d.mkdir()
        opts = f"size={size}" + (",ro" if ro else "")
        subprocess.run(["mount", "-t", "tmpfs", "-o", opts, "tmpfs", str(d)], check=True)
        mounted.append(d)
        return d

    yield mount
    for d in mounted:
        subprocess.run(["umount", "-l", str(d)], check=False)


def on_disk_bytes(root: Path) -> int:
    """What a folder takes on tmpfs: whole 4 KiB pages per file."""
    return sum(-(-len(b) // 4096) * 4096 for b in all_bytes(root).values())


@pytest.fixture(scope="module")
def complete(tmp_path_factory):
    out = tmp_path_factory.mktemp("disk_complete") / "out"
    write_dataset(out)
    return out


def test_full_disk_loses_nothing_and_resume_elsewhere_completes_the_same_bytes(small_disk, tmp_path, complete):
    disk = small_disk(on_disk_bytes(complete) // 2 // 4096 * 4096)  # room for about half the dataset
    out = disk / "ds"
    with pytest.raises(OSError) as info:
        write_dataset(out)
    assert info.value.errno == errno.ENOSPC and info.value.filename.startswith(str(out))
    assert ".scenegen-tmp" not in info.value.filename  # the file being written, not its temporary
    kept = ds.Dataset(out)  # what was recorded is intact: the manifest and its journal agree
    assert 0 < len(kept.views) < 5
    moved = tmp_path / "bigger" / "ds"
    shutil.copytree(out, moved)
    write_dataset(moved, writer=new_writer(moved, resume=True))
    assert all_bytes(moved) == all_bytes(complete)


def test_cli_one_line_for_a_full_disk_and_a_read_only_folder(small_disk, tmp_path):
    from scenegen.cli import main
    from scenegen.errors import os_error_message
    full = small_disk(4096)
    ro = small_disk(65536, ro=True)
    err = OSError(errno.ENOSPC, "No space left on device", str(full / "ds" / "images" / "a.png"))
    assert os_error_message(err).endswith("the disk is full: free space or write to another disk, then run "
                                          "again (a render continues with --resume: everything already "
                                          "written is kept)")
    with pytest.raises(OSError) as info:
        new_writer(ro / "ds")
    assert info.value.errno == errno.EROFS
    assert "read-only: write to another folder" in os_error_message(info.value)
    # the export command writes a folder: a read-only destination is one line, exit 2
    src = tmp_path / "src"
    write_dataset(src)
    code, _, text = run_cli(main, ["export", src, "--format", "tum", "-o", ro / "tum"])
    assert code == 2 and len(text.strip().splitlines()) == 1 and "read-only" in text and "Traceback" not in text
    code, _, text = run_cli(main, ["export", src, "--format", "nerf", "-o", full / "nerf"])
    assert code == 2 and "disk is full" in text and str(full / "nerf") in text, text


TINY = """
name: tiny
render: {spp: 4, max_depth: 2}
objects:
  - {name: floor, shape: {type: plane, size: [3, 3]}, material: {type: diffuse, texture: {type: checkerboard}}}
  - {name: ball, shape: {type: sphere, radius: 0.3}, transform: {translation: [0, 0, 0.3]}, material: {type: diffuse, color: 0.5}}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam: {model: pinhole, size: [96, 72], fx: 80, fy: 80, cx: 48, cy: 36}
views:
  - camera: cam
    orbit: {center: [0, 0, 0], radius_m: 2.0, elevations_deg: [30], count: 4}
"""


@pytest.mark.render
def test_render_on_a_full_disk_then_resume_on_a_larger_one_gives_the_bytes_of_one_run(small_disk, tmp_path):
    from scenegen.cli import main
    spec = tmp_path / "tiny.yaml"
    spec.write_text(TINY)
    ref = tmp_path / "ref"
    assert main(["render", str(spec), "-o", str(ref), "-q"]) == 0
    disk = small_disk(on_disk_bytes(ref) // 2 // 4096 * 4096)
    code, _, err = run_cli(main, ["render", spec, "-o", disk / "ds", "-q"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and "the disk is full" in err
    assert str(disk / "ds") in err and "Traceback" not in err
    moved = tmp_path / "bigger"
    shutil.copytree(disk / "ds", moved)
    assert main(["render", str(spec), "-o", str(moved), "--resume", "-q"]) == 0
    assert all_bytes(moved) == all_bytes(ref)


@pytest.mark.parametrize("code_,advice", [(errno.EACCES, "permission denied: write to a folder you may write to"),
                                          (errno.EDQUOT, "the disk quota is exceeded")])
def test_permission_and_quota_errors_are_one_line_naming_the_target(tmp_path, monkeypatch, code_, advice):
    """Root ignores permissions, so the error is planted where every byte is written
    (scenegen.dataset.files.write_payload): the message names the target file, not its temporary."""
    from scenegen.cli import main
    from scenegen.dataset import files
    src = tmp_path / "src"
    write_dataset(src)

    def refuse(f, data):
        raise OSError(code_, "refused")
    monkeypatch.setattr(files, "write_payload", refuse)
    code, _, err = run_cli(main, ["export", src, "--format", "tum", "-o", tmp_path / "tum"])
    assert code == 2 and len(err.strip().splitlines()) == 1 and advice in err and "scenegen-tmp" not in err
    assert str(tmp_path / "tum") in err and not list((tmp_path / "tum").rglob("*.scenegen-tmp"))
