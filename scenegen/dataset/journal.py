"""``manifest.journal``: what a running writer has recorded since it last wrote manifest.json.

Recording a view must cost the same at view 100,000 as at view 10, so the writer does not rewrite
manifest.json (whose size grows with the run) per view: it appends one line to this journal and
``fdatasync``'s it, and compacts the journal into manifest.json (one atomic rewrite, then the
journal is removed) when the run ends, when views are declared, and when a run resumes. A
finished dataset has no journal, and its manifest.json is byte-identical to one rewritten after
every view.

Each line is self-checking: ``<compact canonical JSON> <SHA-256 of that JSON>\\n``, with ``n``,
the line's position. Line 0 names the manifest it extends (its ``manifest_sha256``); the others
are records: ``{"op": "view", "view": ..., "files": {path: sha256}}`` (the view is complete)
or ``{"op": "file", "path": ..., "sha256": ...}`` (a dataset-level file). After a crash:

* every fully written line counts (each was fsync'd before the writer went on);
* invalid lines at the end, with no valid line after them, are the line being written when the
  process died (a torn tail): dropped, the view is not recorded, a resumed run renders it again
  and writes the same bytes;
* an invalid line followed by a valid one, a line out of sequence, or a journal that does not
  extend the manifest beside it, is not something a crash leaves: :class:`DatasetError`;
* a journal whose manifest was already rewritten with its records (a crash between the rewrite
  and the journal's removal) is stale: every record is already in the manifest, so it is dropped.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from scenegen.dataset.errors import DatasetError
from scenegen.dataset.files import fsync_dir, sha256_bytes
from scenegen.dataset.layout import MANIFEST, MANIFEST_JOURNAL
from scenegen.dataset.manifest import STATUS_COMPLETE, load_manifest, manifest_bytes

JOURNAL_FORMAT = "scenegen-manifest-journal"
JOURNAL_VERSION = 1


def encode_line(n: int, record: dict) -> bytes:
    """One journal line: canonical compact JSON of ``record`` with ``n``, a space, its SHA-256."""
    body = json.dumps({**record, "n": int(n)}, sort_keys=True, separators=(",", ":"), ensure_ascii=True,
                      allow_nan=False).encode("ascii")
    return body + b" " + sha256_bytes(body).encode("ascii") + b"\n"


def _decode_line(line: bytes) -> dict | None:
    """The record of a complete line (without its newline), or None if its checksum or JSON is bad."""
    body, sep, sha = line.rpartition(b" ")
    if not sep or sha256_bytes(body).encode("ascii") != sha:
        return None
    try:
        rec = json.loads(body.decode("ascii"))
    except (UnicodeDecodeError, ValueError):
        return None
    return rec if isinstance(rec, dict) else None


def header(manifest_sha256: str) -> dict:
    return {"op": "begin", "format": JOURNAL_FORMAT, "version": JOURNAL_VERSION, "manifest_sha256": manifest_sha256}


def view_record(view: str, files) -> dict:
    return {"op": "view", "view": view, "files": dict(files)}


def file_record(path: str, sha256: str) -> dict:
    return {"op": "file", "path": path, "sha256": sha256}


@dataclass
class Journal:
    """A parsed journal: its base manifest hash, its records, and what was dropped."""

    manifest_sha256: str
    records: list = field(default_factory=list)
    torn_lines: int = 0  # invalid lines at the end (a write cut by a crash)


def parse_journal(data: bytes, where: str = MANIFEST_JOURNAL) -> Journal:
    """Parse journal bytes; a torn tail is dropped and counted, anything else invalid raises
    :class:`DatasetError` naming the line."""
    lines = data.split(b"\n")
    complete, tail = lines[:-1], lines[-1]  # tail: bytes after the last newline (b"" if none)
    recs = [_decode_line(line) for line in complete]
    last_valid = max((i for i, r in enumerate(recs) if r is not None), default=-1)
    bad = [i for i in range(last_valid) if recs[i] is None]
    if bad:
        raise DatasetError(f"{where}: line {bad[0] + 1} is corrupt (checksum or JSON) and later lines are"
                           " valid: not what a crash leaves; the journal cannot be trusted")
    out_of_place = [i for i, r in enumerate(recs) if r is not None and r.get("n") != i]
    if out_of_place:  # a line lost, repeated or moved: a crash only ever cuts the end
        raise DatasetError(f"{where}: line {out_of_place[0] + 1} is out of sequence (n ="
                           f" {recs[out_of_place[0]].get('n')!r}); the journal cannot be trusted")
    torn = len(recs) - 1 - last_valid + (1 if tail else 0)
    if last_valid < 0:  # not even the header: the journal's first write was cut
        return Journal(manifest_sha256="", records=[], torn_lines=torn)
    head = recs[0]
    if (head.get("op") != "begin" or head.get("format") != JOURNAL_FORMAT
            or head.get("version") != JOURNAL_VERSION or not isinstance(head.get("manifest_sha256"), str)):
        raise DatasetError(f"{where}: line 1 is not a {JOURNAL_FORMAT} version {JOURNAL_VERSION} header")
    records = recs[1:last_valid + 1]
    for i, r in enumerate(records, start=2):
        ok = ((r.get("op") == "view" and isinstance(r.get("view"), str) and isinstance(r.get("files"), dict))
              or (r.get("op") == "file" and isinstance(r.get("path"), str) and isinstance(r.get("sha256"), str)))
        if not ok:
            raise DatasetError(f"{where}: line {i}: unknown record {r.get('op')!r}")
    return Journal(manifest_sha256=head["manifest_sha256"], records=records, torn_lines=torn)


def apply_record(views: dict, files: dict, rec: dict) -> None:
    """Apply one record to a manifest's ``views`` and ``files`` (as the writer recorded it)."""
    if rec["op"] == "file":
        files[rec["path"]] = rec["sha256"]
        return
    view, hashes = rec["view"], rec["files"]
    for rel in views.get(view, {}).get("files", []):
        files.pop(rel, None)
    files.update(hashes)
    views[view] = {"status": STATUS_COMPLETE, "files": sorted(hashes)}


def is_applied(views: dict, files: dict, rec: dict) -> bool:
    """True if the manifest state already holds ``rec`` (replaying it changes nothing)."""
    if rec["op"] == "file":
        return files.get(rec["path"]) == rec["sha256"]
    e = views.get(rec["view"])
    return (e is not None and e.get("status") == STATUS_COMPLETE and sorted(e.get("files", [])) == sorted(rec["files"])
            and all(files.get(r) == s for r, s in rec["files"].items()))


def pending_records(manifest: dict, journal: Journal, where: str = MANIFEST_JOURNAL) -> list:
    """The records of ``journal`` still to apply to ``manifest``: all of them if the journal
    extends this manifest, none if it is stale (already compacted); DatasetError otherwise."""
    if journal.manifest_sha256 == manifest["manifest_sha256"]:
        return list(journal.records)
    views = {v: dict(e) for v, e in manifest["views"].items()}
    files = dict(manifest["files"])
    if all(is_applied(views, files, r) for r in journal.records):
        return []  # compacted into this manifest; the process died before removing the journal
    raise DatasetError(f"{where} extends another {MANIFEST} (manifest_sha256"
                       f" {journal.manifest_sha256[:12]}..., this one {manifest['manifest_sha256'][:12]}...):"
                       " the manifest was replaced while a run was writing; the dataset cannot be trusted")


def read_journal(root) -> Journal | None:
    """The parsed journal of a dataset folder, or None if it has none."""
    path = Path(root) / MANIFEST_JOURNAL
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return None
    return parse_journal(data, str(path))


def load_current_manifest(root) -> dict:
    """manifest.json with the journal of an unfinished run applied (what the writer would compact
    it to), as a manifest dict with its ``manifest_sha256`` recomputed; just the manifest if
    there is no journal. DatasetError for a missing or corrupt manifest or journal. Safe to call
    while a writer runs (a compaction between reading the two files is retried)."""
    root = Path(root)
    if not (root / MANIFEST).is_file() and (root / MANIFEST_JOURNAL).is_file():
        raise DatasetError(f"{root}: {MANIFEST_JOURNAL} without {MANIFEST}: the manifest was removed;"
                           " the dataset cannot be trusted")
    for attempt in range(3):
        before = _file_id(root / MANIFEST)
        m = load_manifest(root)
        journal = read_journal(root)
        if journal is None:
            return m
        try:
            records = pending_records(m, journal, str(root / MANIFEST_JOURNAL))
            break
        except DatasetError:
            if attempt == 2 or _file_id(root / MANIFEST) == before:
                raise
    if not records:
        return m
    views = {v: {"status": e["status"], "files": list(e["files"])} for v, e in m["views"].items()}
    files = dict(m["files"])
    for r in records:
        apply_record(views, files, r)
    return json.loads(manifest_bytes({**m, "views": views, "files": files}))


def _file_id(path: Path):
    try:
        st = path.stat()
    except FileNotFoundError:
        return None
    return st.st_ino, st.st_mtime_ns, st.st_size


class JournalAppender:
    """Appends records to a dataset's journal, fsync'ing each batch (one writer per folder)."""

    def __init__(self, root, manifest_sha256: str):
        self.path = Path(root) / MANIFEST_JOURNAL
        self._fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_APPEND | getattr(os, "O_BINARY", 0),
                           0o666)
        self._n = 0
        self.bytes_written = 0
        self.append([header(manifest_sha256)])
        fsync_dir(self.path.parent)  # the new journal's name is durable before any record counts

    def append(self, records) -> None:
        """Append one line per record, then make them durable (one fdatasync)."""
        data = b"".join(encode_line(self._n + i, r) for i, r in enumerate(records))
        view = memoryview(data)
        while view:
            k = os.write(self._fd, view)
            view = view[k:]
        (getattr(os, "fdatasync", None) or os.fsync)(self._fd)
        self._n += len(records)
        self.bytes_written += len(data)

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None


def remove_journal(root) -> None:
    """Delete a dataset's journal (after its records reached manifest.json), durably."""
    path = Path(root) / MANIFEST_JOURNAL
    try:
        path.unlink()
    except FileNotFoundError:
        return
    fsync_dir(path.parent)
