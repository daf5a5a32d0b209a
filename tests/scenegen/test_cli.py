"""The command line's start-up: its option lists are the project's, and ``--help`` and
``validate`` import only what they need (timings are benchmarks/bench_startup.py's business)."""
import subprocess
import sys
from pathlib import Path

from scenegen import cli
from scenegen.export import FORMATS
from scenegen.spec.model import RENDER_VARIANTS

ROOT = Path(__file__).resolve().parents[2]


def test_option_lists_are_the_projects():
    assert cli.RENDER_VARIANTS == RENDER_VARIANTS
    assert cli.EXPORT_FORMATS == tuple(FORMATS)
    from scenegen.export import PROGRESS_UNITS

    assert set(PROGRESS_UNITS) == set(FORMATS)


def _modules_after(code: str) -> set[str]:
    """The modules a fresh interpreter has imported after running ``code``."""
    out = subprocess.run([sys.executable, "-c", code + "\nimport sys; print('MODULES', *sys.modules)"],
                         capture_output=True, text=True, cwd=ROOT, check=True).stdout
    return set(out.split("MODULES", 1)[1].split())


def _under(mods, packages) -> list[str]:
    return sorted(m for m in mods if any(m == p or m.startswith(p + ".") for p in packages))


def test_help_imports_no_third_party_module():
    mods = _modules_after("from scenegen import cli\ntry:\n    cli.main(['--help'])\nexcept SystemExit:\n    pass")
    assert not _under(mods, ("numpy", "scipy", "cv2", "OpenEXR", "trimesh", "mitsuba", "drjit", "yaml", "dask"))


def test_validate_imports_no_renderer_codec_or_mesh_library():
    mods = _modules_after(f"from scenegen import cli\ncli.main(['validate', {str(ROOT / 'scenes/demo.yaml')!r}])")
    assert "scenegen.spec" in mods
    assert not _under(mods, ("mitsuba", "drjit", "OpenEXR", "trimesh", "dask", "distributed", "scenegen.pipeline",
                             "scenegen.render", "scenegen.export"))
    # a sensor kind names its truth kinds and stream schema (numpy-only modules of the dataset);
    # nothing that encodes, writes or reads a dataset is loaded
    assert set(_under(mods, ("scenegen.dataset",))) <= {
        "scenegen.dataset", "scenegen.dataset.lazy", "scenegen.dataset.truth_kinds", "scenegen.dataset.streams",
        "scenegen.dataset.stream_writer", "scenegen.dataset.layout", "scenegen.dataset.files",
        "scenegen.dataset.codecs", "scenegen.dataset.codecs.npy", "scenegen.dataset.codecs.json"}, \
        _under(mods, ("scenegen.dataset",))
