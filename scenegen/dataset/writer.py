"""Writing a dataset: a view's files (encoded by :mod:`.view_files`) written atomically and
hashed, the manifest kept.

Crash safety: every file is written atomically (:mod:`scenegen.dataset.files`), and a view is
recorded as ``complete`` (one fsync'd line of the manifest's journal, :mod:`.journal`, compacted
into manifest.json when the run ends) only after all of its files are on disk, so a run killed
at any point leaves a consistent dataset that ``resume=True`` can finish. Recording a view costs
the same at any size of the run. Same spec, seed, variant and software: byte-identical datasets,
whatever the order in which views were written.
"""
from __future__ import annotations

import os
import re
import shutil
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from scenegen.dataset.cameras import ViewCamera, cameras_document
from scenegen.dataset.codecs.json import decode_json, encode_json
from scenegen.dataset.codecs.ply import encode_ply
from scenegen.dataset.errors import DatasetError, DatasetMismatchError
from scenegen.dataset.codecs.exr import DEFAULT_EXR_COMPRESSION
from scenegen.dataset.files import atomic_write_bytes, commit_staged, discard_staged, fsync_dirs
from scenegen.dataset.files import remove_stale_temp_files, sha256_bytes
from scenegen.dataset.journal import (
    JournalAppender,
    file_record,
    pending_records,
    read_journal,
    remove_journal,
    view_record,
)
from scenegen.dataset.layout import (
    CAMERAS,
    MANIFEST,
    MANIFEST_JOURNAL,
    check_rel_path,
    check_view_name,
    mesh_path,
    view_paths,
)
from scenegen.dataset.lock import LOCK_NAME, DatasetLock
from scenegen.dataset.manifest import (
    FORMAT,
    FORMAT_VERSION,
    IDENTITY_KEYS,
    STATUS_COMPLETE,
    STATUS_PENDING,
    load_manifest,
    manifest_bytes_and_sha256,
)
from scenegen.dataset.view_files import StagedView, stage_view


class DatasetWriter:
    """Writes a dataset directory; owns its manifest and, until :meth:`close`, the folder's lock
    (:mod:`scenegen.dataset.lock`: a second writer on the folder fails naming this one).

    Typical use::

        w = DatasetWriter(out, spec_sha256=h, seed=s, variant=v, versions=software_versions(),
                          resume=args.resume)
        w.write_cameras(view_cameras, resolved_spec)     # declares every view (status pending)
        for name, mesh in world_meshes.items():
            w.write_mesh(name, mesh)
        for view in view_cameras:
            if w.is_complete(view):
                continue                                  # done by an earlier, interrupted run
            w.write_view(view, image=img, linear_rgb=lin, truth=truth)
        w.close()                                         # the journal compacted into manifest.json

    ``resume=False`` needs ``out_dir`` absent or empty. ``resume=True`` loads an existing manifest,
    which must have been written with the same spec_sha256, seed, variant, format and versions
    (else :class:`DatasetMismatchError`), and its journal (the views a killed run recorded since),
    removes temporary files left by a killed run, and keeps the completed views; a directory
    without a manifest is started afresh if it is empty.
    Views and dataset-level files are recorded in the journal (``manifest.journal``, one
    fsync'd line each); manifest.json is rewritten, and the journal removed, by
    :meth:`write_cameras`, :meth:`close` and a resume.
    Re-writing a file that is already recorded with different content raises
    :class:`DatasetMismatchError` before anything is written: outputs must be deterministic.
    """

    def __init__(self, out_dir, *, spec_sha256: str, seed: int, variant: str,
                 versions: Mapping[str, str], resume: bool = False):
        self.root = Path(out_dir)
        if not (isinstance(spec_sha256, str) and re.fullmatch(r"[0-9a-f]{64}", spec_sha256)):
            raise ValueError(f"spec_sha256 must be 64 lower-case hex digits, got {spec_sha256!r}")
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
            raise TypeError(f"seed must be an int, got {seed!r}")
        identity = {
            "format": FORMAT, "format_version": FORMAT_VERSION, "spec_sha256": spec_sha256,
            "seed": int(seed), "variant": str(variant),
            "versions": {str(k): str(v) for k, v in versions.items()},
        }
        self._identity = identity
        self._views: dict[str, dict] = {}  # view -> {"status": ..., "files": [...]}
        self._files: dict[str, str] = {}  # relative path -> sha256
        self._view_order: list[str] = []
        self._journal: JournalAppender | None = None  # open while records wait for compaction
        self._manifest_sha = ""  # manifest_sha256 of manifest.json as last written
        self.journal_bytes = 0  # bytes appended to journals by this writer (benchmarks)

        self._lock = DatasetLock.acquire(self.root)  # one writer per folder, before anything is touched
        try:
            self._open(identity, resume)
        except BaseException:
            self._lock.release()
            raise

    def _open(self, identity: dict, resume: bool) -> None:
        """Read (resume) or start the folder's manifest; the lock is held."""
        has_manifest = (self.root / MANIFEST).is_file()
        if resume and self.root.is_dir():
            remove_stale_temp_files(self.root)
        if resume and has_manifest:
            m = load_manifest(self.root)
            diffs = [f"{k}: dataset has {m[k]!r}, this run has {identity[k]!r}"
                     for k in IDENTITY_KEYS if m[k] != identity[k]]
            if diffs:
                raise DatasetMismatchError(
                    f"cannot resume {self.root}: it was written by a different run ("
                    + "; ".join(diffs) + "); use a new output directory")
            self._views = {v: {"status": e["status"], "files": list(e["files"])}
                           for v, e in m["views"].items()}
            self._files = dict(m["files"])
            journal = read_journal(self.root)
            records = [] if journal is None else pending_records(m, journal, str(self.root / MANIFEST_JOURNAL))
            self._replay(records)
            resumed_unchanged = not records  # manifest.json already holds this state, byte for byte
        elif self.root.exists() and any(p.name != LOCK_NAME for p in self.root.iterdir()):
            if (self.root / MANIFEST_JOURNAL).is_file() and not has_manifest:
                hint = f"it has a {MANIFEST_JOURNAL} but no {MANIFEST}: the manifest was removed"
            else:
                hint = "render again with --resume to finish it" if has_manifest else "it has no manifest"
            raise DatasetError(f"{self.root} is not empty ({hint}); use a new or empty directory")
        if resume and has_manifest and resumed_unchanged:
            self._manifest_sha = m["manifest_sha256"]  # no rewrite of a large manifest to the same bytes
            remove_journal(self.root)  # a stale one
        else:
            self._write_manifest()

    # --- state
    def is_complete(self, view: str) -> bool:
        """True if ``view`` was fully written (by this or an earlier, interrupted run)."""
        e = self._views.get(view)
        return e is not None and e["status"] == STATUS_COMPLETE

    def file_sha256(self, rel_path: str) -> str | None:
        """The recorded sha256 of a dataset-level file, or None if it is not recorded."""
        return self._files.get(rel_path)

    @property
    def completed_views(self) -> tuple[str, ...]:
        return tuple(sorted(v for v in self._views if self.is_complete(v)))

    @property
    def manifest(self) -> dict:
        """The manifest as last written (a fresh copy)."""
        return decode_json(self._manifest_bytes())

    # --- writing
    def write_cameras(self, views: Mapping[str, ViewCamera], spec: Mapping[str, Any]) -> None:
        """Write cameras.json for every view of the run, in order, and the resolved spec dict.

        Declares each view in the manifest (status ``pending`` until written).
        """
        doc = cameras_document(views, spec)
        self.write_file(CAMERAS, encode_json(doc), _flush=False)
        for name in doc["view_order"]:
            self._views.setdefault(name, {"status": STATUS_PENDING, "files": []})
        self._write_manifest()

    def write_mesh(self, name: str, mesh, *, vertex_normals: bool = False) -> str:
        """Write a world-frame trimesh as binary PLY at ``scene/meshes/<name>.ply``.

        trimesh stores vertices as float32 (the precision Mitsuba renders with); UVs and vertex
        colours are kept; vertex normals only if ``vertex_normals``. Returns the relative path.
        """
        rel = mesh_path(name)
        self.write_file(rel, encode_ply(mesh, vertex_normals=vertex_normals))
        return rel

    def write_file(self, rel_path: str, data: bytes, *, _flush: bool = True) -> str:
        """Write a dataset-level file (not tied to a view), atomically and hashed; returns its
        sha256. For example a calibration target's corner points as JSON."""
        check_rel_path(rel_path)
        sha = sha256_bytes(data)
        old = self._files.get(rel_path)
        if old is not None and old != sha:
            raise DatasetMismatchError(
                f"{rel_path} is already recorded in {self.root} with different content"
                f" (sha256 {old[:12]}... != {sha[:12]}...): outputs are not deterministic, or the"
                " dataset belongs to another run")
        atomic_write_bytes(self.root / rel_path, data)
        self._files[rel_path] = sha
        if _flush and old != sha:
            self._log([file_record(rel_path, sha)])
        return sha

    def record_files(self, file_hashes: Mapping[str, str]) -> None:
        """Record dataset-level files already written (atomically, by
        :class:`scenegen.dataset.files.FileSink` in a worker): ``{relative path: sha256}``, with
        one fsync'd journal batch; a file recorded before with other content raises
        :class:`DatasetMismatchError` before anything is recorded."""
        new = {}
        for rel, sha in file_hashes.items():
            check_rel_path(rel)
            if not (isinstance(sha, str) and re.fullmatch(r"[0-9a-f]{64}", sha)):
                raise ValueError(f"{rel}: sha256 must be 64 lower-case hex digits, got {sha!r}")
            old = self._files.get(rel)
            if old is not None and old != sha:
                raise DatasetMismatchError(f"{rel} is already recorded in {self.root} with different content"
                                           f" (sha256 {old[:12]}... != {sha[:12]}...): outputs are not deterministic")
            if old is None:
                new[rel] = sha
        self._files.update(new)
        if new:
            self._log([file_record(rel, sha) for rel, sha in new.items()])

    def write_view(self, view: str, *, image, linear_rgb, truth, extra_files: Mapping[str, bytes] | None = None,
                   exr_compression: str = DEFAULT_EXR_COMPRESSION) -> None:
        """Encode, write and hash one view's files, then record it (:func:`write_view_files`)."""
        self.commit_views([stage_view(self.root, view, image=image, linear_rgb=linear_rgb, truth=truth,
                                      extra_files=extra_files, exr_compression=exr_compression)])

    def commit_views(self, staged: Sequence[StagedView]) -> None:
        """Record views whose files :func:`stage_view` staged, in order: each checked (as
        :meth:`write_view` does) and renamed, then each distinct directory fsync'd once, then one
        fsync'd journal batch. On an error the views before it are still recorded, the ones from
        it on are not (their temporary files removed)."""
        done: list[StagedView] = []
        try:
            for i, sv in enumerate(staged):
                try:
                    self._check_rerecord(sv.view, sv.hashes)  # before any final name is touched
                    commit_staged(sv.staged)  # durable with the directory fsync below, then recorded
                except BaseException:  # renamed temporaries are gone: removing them is a no-op
                    discard_staged([f for later in staged[i:] for f in later.staged])
                    raise
                done.append(sv)
        finally:
            if done:
                fsync_dirs([path for sv in done for _, path in sv.staged])
                self.record_views({sv.view: sv.hashes for sv in done})

    def record_view(self, view: str, file_hashes: Mapping[str, str]) -> None:
        """Mark ``view`` complete with the files (``{relative path: sha256}``) already written,
        e.g. by :func:`write_view_files` in a worker: one fsync'd journal line."""
        if self._is_recorded(view, file_hashes):
            return  # the same files again (a rewrite of a complete view): nothing new to record
        self._record(view, file_hashes)
        self._log([view_record(view, file_hashes)])

    def record_views(self, views: Mapping[str, Mapping[str, str]]) -> None:
        """:meth:`record_view` for several views (``{view: {relative path: sha256}}``, in order)
        with one fsync: a client recording many workers' views batches what is ready. Nothing is
        recorded if any view is invalid."""
        views = {v: h for v, h in views.items() if not self._is_recorded(v, h)}
        snapshot = ({v: {"status": e["status"], "files": list(e["files"])} for v, e in self._views.items()},
                    dict(self._files))
        try:
            for view, file_hashes in views.items():
                self._record(view, file_hashes)
        except Exception:
            self._views, self._files = snapshot
            raise
        if views:
            self._log([view_record(v, h) for v, h in views.items()])

    def _is_recorded(self, view: str, file_hashes: Mapping[str, str]) -> bool:
        e = self._views.get(view)
        return (e is not None and e["status"] == STATUS_COMPLETE and sorted(e["files"]) == sorted(file_hashes)
                and all(self._files.get(r) == h for r, h in file_hashes.items()))

    def _record(self, view: str, file_hashes: Mapping[str, str]) -> None:
        check_view_name(view)
        for rel, sha in file_hashes.items():
            check_rel_path(rel)
            if not (isinstance(sha, str) and re.fullmatch(r"[0-9a-f]{64}", sha)):
                raise ValueError(f"{rel}: sha256 must be 64 lower-case hex digits, got {sha!r}")
        missing = sorted(set(view_paths(view).values()) - set(file_hashes))
        if missing:
            raise ValueError(f"view {view!r}: no hash for {missing}")
        self._check_rerecord(view, file_hashes)
        for rel in self._views.get(view, {}).get("files", []):
            self._files.pop(rel, None)
        self._files.update(file_hashes)
        self._views[view] = {"status": STATUS_COMPLETE, "files": sorted(file_hashes)}

    def close(self) -> None:
        """Compact the journal into manifest.json (atomically) and remove it: a finished dataset."""
        try:
            self._write_manifest()
        finally:
            self._lock.release()

    def abort(self) -> None:
        """Release the folder without compacting (after a failure: the journal already holds
        every recorded view, so ``--resume`` continues from here)."""
        if self._journal is not None:
            self._journal.close()
            self._journal = None
        self._lock.release()

    def discard(self) -> bool:
        """After a failure: remove the folder when this writer created it and completed no view
        in it (so the next run starts afresh instead of being told the folder is not empty);
        otherwise :meth:`abort` (``--resume`` finishes it). Returns True if the folder was removed.

        Only a folder this writer's own ``mkdir`` created, and whose lock it has held since, is
        removed: everything in it is this run's. It is first renamed out of the way (atomically,
        the lock still held), so a writer starting meanwhile makes a new folder of its own
        instead of finding this one half deleted.
        """
        if self._lock.path is None or not self._lock.created_root or self.completed_views:
            self.abort()
            return False
        if self._journal is not None:
            self._journal.close()
            self._journal = None
        doomed = self.root.with_name(f".{self.root.name}.discarded-{os.getpid()}-{id(self):x}")
        try:
            os.rename(self.root, doomed)
        except OSError:
            self.abort()
            return False
        self._lock.path = doomed / LOCK_NAME  # release must not unlink a new writer's lock file
        try:
            shutil.rmtree(doomed, ignore_errors=True)
        finally:
            self._lock.release()
        return True

    def __enter__(self) -> "DatasetWriter":
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()

    # --- internals
    def _check_rerecord(self, view: str, hashes: Mapping[str, str]) -> None:
        check_view_name(view)
        if self.is_complete(view):
            old = {rel: self._files.get(rel) for rel in self._views[view]["files"]}
            if old != dict(hashes):
                changed = sorted(r for r in set(old) | set(hashes) if old.get(r) != hashes.get(r))
                raise DatasetMismatchError(
                    f"view {view!r} is already complete in {self.root} with different files"
                    f" {changed}: outputs are not deterministic, or the dataset belongs to another run")
        own = set(self._views.get(view, {}).get("files", []))
        taken = sorted(rel for rel in hashes if rel in self._files and rel not in own)
        if taken:
            raise ValueError(f"view {view!r}: files {taken} already belong to another view or the dataset")

    def _manifest_bytes(self) -> bytes:
        return self._manifest_bytes_and_sha256()[0]

    def _manifest_bytes_and_sha256(self) -> tuple[bytes, str]:
        body = dict(self._identity)
        body["views"] = {v: {"status": e["status"], "files": sorted(e["files"])} for v, e in self._views.items()}
        body["files"] = dict(self._files)
        return manifest_bytes_and_sha256(body)

    def _write_manifest(self) -> None:
        """Rewrite manifest.json from the writer's state, then drop the journal it now contains."""
        data, self._manifest_sha = self._manifest_bytes_and_sha256()
        atomic_write_bytes(self.root / MANIFEST, data)
        if self._journal is not None:
            self._journal.close()
            self._journal = None
        remove_journal(self.root)  # also a stale one a killed run left

    def _log(self, records) -> None:
        """Append records to the journal (started on first use after a manifest rewrite)."""
        if self._journal is None:
            self._journal = JournalAppender(self.root, self._manifest_sha)
        before = self._journal.bytes_written
        self._journal.append(records)
        self.journal_bytes += self._journal.bytes_written - before

    def _replay(self, records) -> None:
        """Apply a killed run's journal records, checked as when they were first recorded."""
        for rec in records:
            try:
                if rec["op"] == "view":
                    self._record(rec["view"], rec["files"])
                else:
                    check_rel_path(rec["path"])
                    if not re.fullmatch(r"[0-9a-f]{64}", rec["sha256"]):
                        raise ValueError(f"{rec['path']}: sha256 must be 64 lower-case hex digits")
                    self._files[rec["path"]] = rec["sha256"]
            except (ValueError, TypeError) as e:
                raise DatasetError(f"{self.root / MANIFEST_JOURNAL}: record {rec.get('n')}: {e}") from None
