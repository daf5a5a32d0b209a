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
import numpy as np  # noqa: E402
from test_dataset import SPEC, VIEWS, H, W, make_view, new_writer, view_cameras, write_dataset  # noqa: E402

from scenegen.dataset.codecs import TrackSet, encode_json  # noqa: E402
from scenegen.dataset.files import sha256_bytes  # noqa: E402
from scenegen.dataset.layout import SEQUENCE_INDEX, tracks_path  # noqa: E402
from scenegen.dataset.manifest import manifest_bytes  # noqa: E402
from scenegen.dataset.sequence import SEQUENCE_FORMAT, SEQUENCE_FORMAT_VERSION  # noqa: E402

__all__ = ["VIEWS", "write_dataset", "resign", "run_cli", "tree", "STREAM", "good_tracks", "write_sequence_dataset"]


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


#: The track stream of :func:`write_sequence_dataset`: its frames are two of VIEWS.
STREAM, STREAM_FRAMES = "cam0", ("cam0_000", "cam0_001")


def good_tracks() -> TrackSet:
    """Three truth tracks over :data:`STREAM_FRAMES`, one occluded in the second frame."""
    xy = np.array([[[1.0, 1.0], [1.5, 1.0]], [[2.0, 3.0], [2.0, 3.5]], [[4.0, 2.0], [np.nan, np.nan]]], np.float32)
    occ = np.array([[False, False], [False, False], [False, True]])
    return TrackSet(query_points=[[0, y, x] for x, y in xy[:, 0]], tracks_xy=xy, occluded=occ, out_of_frame=occ,
                    image_size=[W, H], frame_names=list(STREAM_FRAMES))


def write_sequence_dataset(out: Path, truth_npz: bytes) -> Path:
    """A dataset of VIEWS (scenegen's writer) with a sequence index naming one track stream,
    :data:`STREAM`, whose truth tracks file holds ``truth_npz``; the path of that file."""
    w = new_writer(out)
    w.write_cameras(view_cameras(), SPEC)
    for i, v in enumerate(VIEWS):
        w.write_view(v, **make_view(i))
    index = {"format": SEQUENCE_FORMAT, "format_version": SEQUENCE_FORMAT_VERSION, "timestamps_s": [0.0, 0.05],
             "pairs": [], "tracks": [{"stream": STREAM, "frames": list(STREAM_FRAMES)}],
             "files": [tracks_path(STREAM)]}
    w.write_file(tracks_path(STREAM), truth_npz)
    w.write_file(SEQUENCE_INDEX, encode_json(index))
    w.close()
    return out / tracks_path(STREAM)
