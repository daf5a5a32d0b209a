"""The Python API as docs/python_api.md shows it: its example runs, and rendering the spec built
in code writes the same bytes as `scenegen render` of its to_yaml text."""
import json
import re
from pathlib import Path

import pytest

from scenegen.cli import main

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.render


def test_the_documented_example_renders_as_the_cli_does(tmp_path, monkeypatch):
    code = re.search(r"```python\n(.*?)```", (ROOT / "docs/python_api.md").read_text(), re.S).group(1)
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    exec(compile(code, "docs/python_api.md", "exec"), ns)
    assert ns["summary"].views_rendered == 3
    (tmp_path / "two_balls.yaml").write_text(ns["to_yaml"](ns["spec"]))
    assert main(["render", "two_balls.yaml", "-o", "cli", "-q"]) == 0
    api = json.loads((tmp_path / "out/two_balls/manifest.json").read_text())
    cli = json.loads((tmp_path / "cli/manifest.json").read_text())
    assert api["files"] == cli["files"] and len(api["files"]) > 10  # every file, by SHA-256
    assert api["spec_sha256"] == cli["spec_sha256"]
