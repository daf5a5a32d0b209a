"""Shared helpers of the hostile-input tests: a small dataset written by scenegen's own writer,
re-signing a tampered manifest (what an attacker who edits a dataset can do), running the CLIs
in-process and checking that no traceback escaped."""
from __future__ import annotations

import io
import json
import sys
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "scenegen" / "dataset"))  # test_dataset's fixtures
from test_dataset import VIEWS, write_dataset  # noqa: E402

from scenegen.dataset.files import sha256_bytes  # noqa: E402
from scenegen.dataset.manifest import manifest_bytes  # noqa: E402

__all__ = ["VIEWS", "write_dataset", "resign", "run_cli", "tree"]


def resign(root: Path, edit_manifest=None) -> None:
    """Recompute the file hashes and the manifest's own hash after files were edited (the manifest
    is a checksum, not a signature: anyone can do this), optionally editing the manifest first."""
    m = json.loads((root / "manifest.json").read_text())
    m.pop("manifest_sha256")
    if edit_manifest:
        edit_manifest(m)
    for rel in list(m["files"]):
        p = root / rel
        if p.is_file():
            m["files"][rel] = sha256_bytes(p.read_bytes())
    (root / "manifest.json").write_bytes(manifest_bytes(m))


def run_cli(main, argv) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``main(argv)`` run in-process; SystemExit counts as a return."""
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else 2
    return code, out.getvalue(), err.getvalue()


def tree(root: Path) -> set[str]:
    """Every file under ``root`` (relative POSIX paths)."""
    return {p.relative_to(root).as_posix() for p in Path(root).rglob("*") if p.is_file()}
