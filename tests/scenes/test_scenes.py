"""Every bundled scene validates and renders its first frame (at 4 spp)."""
from pathlib import Path

import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset, verify

SCENES = sorted(str(p.relative_to(Path(__file__).parents[2]))
                for p in (Path(__file__).parents[2] / "scenes").rglob("*.yaml"))


def test_scene_library_is_not_empty():
    assert "scenes/demo.yaml" in SCENES and len(SCENES) >= 4


@pytest.mark.render
@pytest.mark.parametrize("spec", SCENES)
def test_scene_renders(spec, tmp_path):
    root = Path(__file__).parents[2]
    assert main(["validate", str(root / spec)]) == 0
    out = tmp_path / "out"
    assert main(["render", str(root / spec), "-o", str(out), "--frames", "0", "--spp", "4", "-q"]) == 0
    d = Dataset(out)
    assert len(d.views) >= 1
    for view in d.views:
        t = d.truth(view)
        assert t["valid"].any(), f"{spec}: view {view} sees nothing"
        assert np.isfinite(d.linear_image(view)).all()
    report = verify(out)  # views outside --frames are pending, not missing
    assert not report.missing and not report.corrupted and not report.unexpected
