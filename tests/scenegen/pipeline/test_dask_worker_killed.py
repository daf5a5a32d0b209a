"""A Dask worker of an external ``dask scheduler`` killed in the middle of a write: the run still
succeeds with the serial run's dataset, and the client removes the temporary file the dead worker
left, so ``scenegen verify`` passes without a ``--resume``."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

from scenegen.cli import main
from scenegen.dataset import verify
from scenegen.dataset.files import TEMP_SUFFIX

sys.path.insert(0, str(Path(__file__).parent))
from external_dask import external_cluster, file_hashes  # noqa: E402

SPEC = """
name: killed_worker
render: {spp: 4, max_depth: 2}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: noise, params: {size_px: 32}}}
  - name: ball
    shape: {type: sphere, radius: 0.3}
    transform: {translation: [0, 0, 0.3]}
lights:
  - {type: point, position: [1, -1, 2], intensity: 5}
cameras:
  cam: {model: pinhole, size: [32, 24], fx: 28}
views:
  - camera: cam
    orbit: {center: [0, 0, 0.2], radius_m: 2.0, elevations_deg: [35], count: 8}
crossview: {pairs: none}
"""

# Loaded by the doomed worker (dask worker --preload): at its first atomic rename of a dataset
# temporary file (the file is complete and fsync'ed, not yet renamed) the process SIGKILLs itself.
# Dask may execute a preload twice (from the given path and from its scratch-space copy): the
# original os.replace is kept on the os module, so a second load does not wrap the first wrapper
# (which recursed without end on every other rename, e.g. the asset cache's when it was cold).
DIE_MID_WRITE = f'''
import os, signal
_replace = getattr(os, "_scenegen_test_original_replace", os.replace)
os._scenegen_test_original_replace = _replace
def _replace_then_die(src, dst, *args, **kwargs):
    if str(src).endswith("{TEMP_SUFFIX}"):
        with open(os.environ["SCENEGEN_TEST_KILLED_AT"], "w") as f:
            f.write(str(src))
        os.kill(os.getpid(), signal.SIGKILL)
    return _replace(src, dst, *args, **kwargs)
os.replace = _replace_then_die
'''


@pytest.mark.render
def test_worker_killed_mid_write_leaves_no_temp_file(tmp_path):
    spec = tmp_path / "scene.yaml"
    spec.write_text(SPEC)
    (tmp_path / "die_mid_write.py").write_text(DIE_MID_WRITE)
    killed_at = tmp_path / "killed_at.txt"
    workers = [(["--name", "doomed", "--preload", str(tmp_path / "die_mid_write.py")],
                {"SCENEGEN_TEST_KILLED_AT": str(killed_at)}), (["--name", "survivor"], {})]
    with external_cluster(tmp_path, workers) as (addr, procs):
        out = tmp_path / "dist"
        assert main(["render", str(spec), "-o", str(out), "-q", "--scheduler", addr]) == 0
        assert killed_at.is_file(), "the doomed worker never wrote (the test needs it killed mid-write)"
        left = Path(killed_at.read_text())
        assert left.parent.parent == out and left.name.endswith(TEMP_SUFFIX)
        procs[0].wait(timeout=30)
        assert procs[0].returncode == -9  # SIGKILL, with its temporary file complete on disk
        assert not left.exists() and not list(out.rglob(f"*{TEMP_SUFFIX}"))
        assert verify(out).ok
        assert main(["verify", str(out)]) == 0
    serial = tmp_path / "serial"
    assert main(["render", str(spec), "-o", str(serial), "-q"]) == 0
    assert file_hashes(out) == file_hashes(serial)
