"""Fixtures of the imaging tests."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[3] / "docs" / "image_formation.md"


@pytest.fixture(scope="session")
def develop_from_record():
    """``develop(raw_mosaic, isp) -> image``: the ISP steps exactly as docs/image_formation.md
    ("The ISP: from the raw mosaic to the delivered image") prints them, numpy and OpenCV only,
    no scenegen code; the tests run the documented code itself."""
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)
    code = [b for b in blocks if "def develop(raw, isp):" in b]
    assert len(code) == 1, "docs/image_formation.md must hold one `def develop(raw, isp):` block"
    namespace: dict = {}
    exec(compile(code[0], str(DOC), "exec"), namespace)  # noqa: S102 - our own docs
    return namespace["develop"]
