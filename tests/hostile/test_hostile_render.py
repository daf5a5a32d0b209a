"""A failed render (issue 18): asset errors name the spec's file:line in render as in validate, and
a run that fails before completing any view leaves no folder behind to block the next run; one
that fails later keeps what it completed for ``--resume``."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import run_cli  # noqa: E402

TINY = """
name: tiny
render: {spp: 4, max_depth: 2}
objects:
  - {name: ball, shape: {type: sphere, radius: 0.3}, material: {type: diffuse, color: 0.5}}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam: {model: pinhole, size: [64, 48], fx: 60, fy: 60, cx: 32, cy: 24}
views:
  - camera: cam
    orbit: {center: [0, 0, 0], radius_m: 2.0, elevations_deg: [30], count: 3}
"""


@pytest.mark.render
@pytest.mark.parametrize("fail_at", [0, 2])
def test_a_failed_render_blocks_nothing(tmp_path, monkeypatch, fail_at):
    from scenegen.cli import main
    from scenegen.dataset import Dataset
    from scenegen.pipeline import run
    spec = tmp_path / "tiny.yaml"
    spec.write_text(TINY)
    out = tmp_path / "out"
    real = run.render_view_data

    def failing(spec_, built, index, v, **kw):
        if index == fail_at:
            raise ValueError(f"planted failure at view {index}")
        return real(spec_, built, index, v, **kw)

    monkeypatch.setattr(run, "render_view_data", failing)
    code, _, err = run_cli(main, ["render", spec, "-o", out, "-q"])
    assert code == 2 and "planted failure" in err
    monkeypatch.setattr(run, "render_view_data", real)
    if fail_at == 0:
        assert not out.exists()  # nothing was completed: nothing left to block the next run
        assert main(["render", str(spec), "-o", str(out), "-q"]) == 0
    else:
        assert len(Dataset(out).views) == fail_at  # completed views are kept
        code, _, err = run_cli(main, ["render", spec, "-o", out, "-q"])
        assert code == 2 and "--resume" in err
        assert main(["render", str(spec), "-o", str(out), "--resume", "-q"]) == 0
    assert len(Dataset(out).views) == 3


@pytest.mark.render
def test_render_names_the_spec_line_of_a_bad_mesh(tmp_path):
    from scenegen.cli import main
    from scenegen.render import load_scene
    from scenegen.spec import load_spec
    from scenegen.errors import SpecError
    (tmp_path / "nan.obj").write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    spec = tmp_path / "m.yaml"
    spec.write_text(TINY.replace("lights:", "  - name: thing\n    mesh: nan.obj\n"
                                            "    material: {type: diffuse, color: 0.5}\nlights:"))
    with pytest.raises(SpecError, match=r"m\.yaml:6: objects\[1\]: object 'thing': .*vertex 2 is not finite"):
        load_scene(load_spec(spec))
    code, _, err = run_cli(main, ["render", spec, "-o", tmp_path / "o", "-q"])
    assert code == 2 and "m.yaml:6: objects[1]" in err and not (tmp_path / "o").exists()
