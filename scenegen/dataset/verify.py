"""``scenegen verify``: re-hash every file listed in a dataset's manifest and compare the folder
with it (missing, corrupted and unexpected files, incomplete views, inconsistent listings).

A folder with a ``manifest.journal`` is a run that did not finish: that is reported, the journal
is checked (a corrupt or torn line is reported) and its records count as listed."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from scenegen.dataset.codecs.json import read_json
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.files import sha256_file
from scenegen.dataset.journal import apply_record, pending_records, read_journal
from scenegen.dataset.layout import CAMERAS, MANIFEST, MANIFEST_JOURNAL, STREAMS, check_rel_path, view_paths
from scenegen.dataset.manifest import FORMAT, FORMAT_VERSION, STATUS_COMPLETE, manifest_integrity_error
from scenegen.dataset.streams import check_stream_document


@dataclass(frozen=True, kw_only=True)
class VerifyReport:
    """Result of :func:`verify`. Paths are relative POSIX paths, sorted."""

    ok: bool  # True iff every list below is empty
    missing: tuple[str, ...]  # listed in the manifest, absent on disk
    corrupted: tuple[str, ...]  # present, but the bytes differ from the recorded sha256
    unexpected: tuple[str, ...]  # on disk but not listed (e.g. files of unfinished views)
    incomplete_views: tuple[str, ...]  # declared views not marked complete
    problems: tuple[str, ...]  # anything else (unreadable manifest, inconsistent listings)
    files_checked: int  # number of files re-hashed

    def summary(self) -> str:
        lines = [f"{'OK' if self.ok else 'FAILED'}: {self.files_checked} files checked"]
        for label, items in (("missing", self.missing), ("corrupted", self.corrupted),
                             ("unexpected", self.unexpected),
                             ("incomplete views", self.incomplete_views), ("problems", self.problems)):
            if items:
                lines.append(f"{label} ({len(items)}):")
                lines.extend(f"  {x}" for x in items)
        return "\n".join(lines)


def _report(missing=(), corrupted=(), unexpected=(), incomplete=(), problems=(), checked=0):
    lists = [tuple(sorted(x)) for x in (missing, corrupted, unexpected, incomplete)]
    return VerifyReport(ok=not any(lists) and not problems, missing=lists[0], corrupted=lists[1],
                        unexpected=lists[2], incomplete_views=lists[3], problems=tuple(problems),
                        files_checked=checked)


def verify(out_dir) -> VerifyReport:
    """Re-hash every file listed in the manifest and compare the directory with it.

    The manifest checks itself (``manifest_sha256``); if it is corrupt nothing else can be
    trusted, and only ``manifest.json`` is reported.
    """
    root = Path(out_dir)
    mpath = root / MANIFEST
    if not root.is_dir():
        return _report(problems=[f"{root} is not a directory"])
    if not mpath.is_file():
        extra = f" (but a {MANIFEST_JOURNAL}: the manifest was removed)" if (root / MANIFEST_JOURNAL).is_file() else ""
        return _report(missing=[MANIFEST], problems=[f"no {MANIFEST}: not a scenegen dataset{extra}"])
    m, err = manifest_integrity_error(mpath.read_bytes())
    if err:
        return _report(corrupted=[MANIFEST],
                       problems=[f"{MANIFEST}: {err}; other files not checked"])
    problems = []
    if m["format"] != FORMAT or m["format_version"] != FORMAT_VERSION:
        problems.append(f"format {m['format']!r} version {m['format_version']!r} is not"
                        f" {FORMAT!r} version {FORMAT_VERSION}")
    m, journal_problems = _with_journal(root, m)
    problems += journal_problems

    missing, corrupted = [], []
    for rel, sha in m["files"].items():
        try:
            check_rel_path(rel)
        except ValueError as e:
            problems.append(str(e))
            continue
        p = root / rel
        if not p.is_file():
            missing.append(rel)
        elif sha256_file(p) != sha:
            corrupted.append(rel)
    listed = set(m["files"]) | {MANIFEST, MANIFEST_JOURNAL}
    unexpected = [p.relative_to(root).as_posix() for p in root.rglob("*")
                  if p.is_file() and p.relative_to(root).as_posix() not in listed]

    incomplete = [v for v, e in m["views"].items() if e.get("status") != STATUS_COMPLETE]
    for v, e in m["views"].items():
        if e.get("status") == STATUS_COMPLETE:
            unlisted = sorted(set(view_paths(v).values()) - set(e.get("files", [])))
            unlisted += [r for r in e.get("files", []) if r not in m["files"]]
            if unlisted:
                problems.append(f"view {v!r} is complete but has no hash for {unlisted}")
    problems += _stream_problems(root, m["files"], set(missing + corrupted))
    if CAMERAS in m["files"] and CAMERAS not in missing + corrupted:
        try:
            declared = read_json(root / CAMERAS)["view_order"]
        except (ValueError, KeyError, TypeError) as e:
            problems.append(f"{CAMERAS}: unreadable ({e})")
        else:
            undeclared = sorted(set(declared) - set(m["views"]))
            if undeclared:
                problems.append(f"views in {CAMERAS} but not in {MANIFEST}: {undeclared}")
    return _report(missing, corrupted, unexpected, incomplete, problems, checked=len(m["files"]))


def _stream_problems(root: Path, files, bad: set) -> list[str]:
    """Streams: each document checked (:func:`check_stream_document`) and its chunks listed; chunks
    of a stream without a document are an unfinished stream."""
    problems, documented = [], set()
    for rel in sorted(files):
        parts = rel.split("/")
        if len(parts) != 3 or parts[0] != STREAMS or parts[2] != "stream.json" or rel in bad:
            continue
        try:
            doc = read_json(root / rel)
            check_stream_document(doc, parts[1])
        except (ValueError, OSError) as e:
            problems.append(f"{rel}: {e}")
            continue
        documented.add(parts[1])
        unlisted = [c["path"] for c in doc["chunks"] if c["path"] not in files]
        if unlisted:
            problems.append(f"{rel}: chunks not listed in {MANIFEST}: {unlisted}")
    orphans = sorted({r.split("/")[1] for r in files if r.startswith(f"{STREAMS}/") and r.count("/") == 2}
                     - documented)
    if orphans:
        problems.append(f"streams with chunks but no stream.json (unfinished): {orphans}")
    return problems


def _with_journal(root: Path, m: dict) -> tuple[dict, list[str]]:
    """The manifest with an unfinished run's journal applied, and what to report about it."""
    try:
        journal = read_journal(root)
        if journal is None:
            return m, []
        records = pending_records(m, journal, MANIFEST_JOURNAL)
    except DatasetError as e:
        return m, [f"{e}; checked against {MANIFEST} alone"]
    problems = [(f"{MANIFEST_JOURNAL}: the run did not finish ({len(journal.records)} records not yet in"
                 f" {MANIFEST}); run it again with --resume")]
    if journal.torn_lines:
        problems.append(f"{MANIFEST_JOURNAL}: {journal.torn_lines} incomplete last line(s) (a write cut by a"
                        " crash; dropped by --resume)")
    views = {v: {"status": e["status"], "files": list(e["files"])} for v, e in m["views"].items()}
    files = dict(m["files"])
    for r in records:
        apply_record(views, files, r)
    return {**m, "views": views, "files": files}, problems
