"""Every case of the hostile spec corpus (tests/hostile/spec_corpus.py) through ``scenegen
validate`` in-process: the expected exit code, the expected fragment, one line, no traceback,
within a second."""
from __future__ import annotations

import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import run_cli  # noqa: E402
from spec_corpus import BASE, CASES, write_assets  # noqa: E402

from scenegen.cli import main  # noqa: E402


def test_the_corpus_is_large_enough_and_its_base_is_valid(tmp_path):
    assert len(CASES) >= 120 and len({c[0] for c in CASES}) == len(CASES)
    (tmp_path / "base.yaml").write_text(BASE)
    assert run_cli(main, ["validate", tmp_path / "base.yaml"])[0] == 0


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("spec_corpus")
    write_assets(d)
    return d


@pytest.mark.parametrize("cid,edit,fragment,code", CASES, ids=[c[0] for c in CASES])
def test_hostile_spec(folder, cid, edit, fragment, code):
    spec = folder / f"{cid}.yaml"
    if isinstance(edit, bytes):
        spec.write_bytes(edit)
    else:
        spec.write_bytes(edit(BASE).encode("utf-8"))
    t0 = time.perf_counter()
    got, out, err = run_cli(main, ["validate", spec])
    seconds = time.perf_counter() - t0
    assert "Traceback" not in err and got == code, (got, err)
    if code == 2:
        # the spec's file:line first, or a mesh file's own (file:line of the name in it) then the spec's
        assert len(err.strip().splitlines()) == 1 and (err.startswith(f"scenegen: error: {spec}")
                                                       or f"(the mesh of {spec}:" in err), err
        assert fragment in err, err
    else:
        assert fragment in out
    assert seconds < 5.0  # well under a second on an idle machine; CI runners are shared
