"""Atomic, durable writes and content hashes: how every file of a dataset (and every report of
the evaluator) reaches the disk.

A write first has the whole content in memory, then goes to a temporary file in the destination
directory, is ``fsync``'ed, renamed over the final name (``os.replace``) and the directory is
``fsync``'ed. A reader sees either the old file or the complete new one, never a partial file,
even if the process is killed (SIGKILL) or the machine loses power mid-write. A killed write can
leave a temporary file named ``.<name>.<random>.scenegen-tmp`` beside the target
(:func:`remove_stale_temp_files`).
"""
from __future__ import annotations

import hashlib
import os
import secrets
from pathlib import Path
from typing import BinaryIO, Callable

from scenegen.dataset.layout import check_rel_path

#: Suffix of the temporary files made by :func:`atomic_write` (``.<name>.<random>.scenegen-tmp``).
TEMP_SUFFIX = ".scenegen-tmp"

_HASH_CHUNK = 1 << 20  # bytes read at a time by sha256_file


# --- atomic writes ----------------------------------------------------------------------------
def fsync_dir(directory: Path) -> None:
    """Make a rename in ``directory`` durable (no-op where directories cannot be opened)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:  # e.g. Windows
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write(path, write_fn: Callable[[BinaryIO], None]) -> None:
    """Write ``path`` atomically by calling ``write_fn(f)`` on a temporary binary file.

    The temporary file is in the same directory as ``path`` (created with its parents if needed),
    is flushed and fsync'ed, then renamed over ``path``. If ``write_fn`` raises, the temporary file
    is removed, ``path`` is left exactly as it was (old content or absent) and the error propagates.
    New files get the usual permissions (0o666 minus the umask).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}{TEMP_SUFFIX}"
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    try:
        with os.fdopen(fd, "wb") as f:
            write_fn(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as e:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        if isinstance(e, OSError) and e.errno is not None:
            raise named_os_error(e, path) from None
        raise
    fsync_dir(path.parent)


def named_os_error(e: OSError, path: Path) -> OSError:
    """The same error naming the file being written (not its temporary file, not nothing: a
    full disk's write error carries no file name). Its class follows the errno."""
    return OSError(e.errno, e.strerror or str(e), str(path))


def write_payload(f: BinaryIO, data: bytes) -> None:
    """Write a file's bytes into its open temporary file (the one place every byte goes through)."""
    f.write(data)


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_write`)."""
    data = bytes(data) if not isinstance(data, bytes) else data
    atomic_write(path, lambda f: write_payload(f, data))


def atomic_write_files(items) -> None:
    """Write several files (``{path: bytes}``), each atomically as :func:`atomic_write` does, with
    one directory fsync per directory instead of one per file: every temporary file is written and
    fsync'ed, then they are renamed in order, then each directory is fsync'ed once, so all of them
    are durable when this returns (a view's files, before the view is recorded). If anything
    fails, the temporary files not yet renamed are removed; renamed ones stay, each complete."""
    commit_staged(stage_files(items))
    fsync_dirs(items)


def stage_files(items) -> list[tuple[Path, Path]]:
    """The first half of :func:`atomic_write_files`: write and fsync each file's bytes to a
    temporary file beside it; returns ``[(temporary, final path)]`` for :func:`commit_staged`.
    Safe on worker threads (touches no final name). On an error, nothing staged is left."""
    staged: list[tuple[Path, Path]] = []
    try:
        for path, data in items.items():
            path = Path(path)
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}{TEMP_SUFFIX}"
            staged.append((tmp, path))
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
            with os.fdopen(fd, "wb") as f:
                write_payload(f, data)
                f.flush()
                os.fsync(f.fileno())
    except BaseException as e:
        discard_staged(staged)
        if isinstance(e, OSError) and e.errno is not None and staged:
            raise named_os_error(e, staged[-1][1]) from None
        raise
    return staged


def commit_staged(staged: list[tuple[Path, Path]]) -> None:
    """Rename staged files over their final names, in order; on an error the ones not yet renamed
    are removed (renamed ones stay, each complete). Their directories still need
    :func:`fsync_dirs` before the renames are durable."""
    staged = list(staged)
    try:
        while staged:
            tmp, path = staged[0]
            os.replace(tmp, path)
            staged.pop(0)
    except BaseException as e:
        discard_staged(staged)
        if isinstance(e, OSError) and e.errno is not None and staged:
            raise named_os_error(e, staged[0][1]) from None
        raise


def discard_staged(staged) -> None:
    """Remove staged temporary files (a view that will not be committed)."""
    for tmp, _ in staged:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass


def fsync_dirs(paths) -> None:
    """fsync each distinct parent directory of ``paths`` once (renames in them made durable)."""
    for directory in dict.fromkeys(Path(p).parent for p in paths):
        fsync_dir(directory)


def copy_file(src, dst) -> None:
    """Copy ``src`` to ``dst`` atomically (an export's copy of a dataset file): a read error names
    ``src``, a write error (full disk, read-only folder) names ``dst``."""
    atomic_write_bytes(dst, Path(src).read_bytes())


def remove_stale_temp_files(root) -> list[Path]:
    """Delete temporary files left under ``root`` by killed :func:`atomic_write` calls.

    Only files named ``.<name>.<random>.scenegen-tmp`` are touched. Call it only when no writer is
    running on ``root``. Returns the removed paths.
    """
    removed = []
    for p in sorted(Path(root).rglob(f".*{TEMP_SUFFIX}")):
        if p.is_file():
            p.unlink()
            removed.append(p)
    return removed


# --- hashes -----------------------------------------------------------------------------------
def sha256_bytes(data: bytes) -> str:
    """Lower-case hex SHA-256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def sha256_file(path) -> str:
    """Lower-case hex SHA-256 of the file's bytes (read in 1 MiB chunks)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(_HASH_CHUNK):
            h.update(chunk)
    return h.hexdigest()


def read_decoded(path, decode):
    """``decode(bytes of path)``; a ValueError of the decoder names the file."""
    try:
        return decode(Path(path).read_bytes())
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None


class FileSink:
    """Dataset-level files written atomically under ``root`` by a process that does not own the
    dataset's writer (a Dask worker): ``files`` keeps ``{relative path: sha256}`` for the owner to
    record (:meth:`scenegen.dataset.writer.DatasetWriter.record_files`)."""

    def __init__(self, root):
        self.root = Path(root)
        self.files: dict[str, str] = {}

    def write_file(self, rel_path: str, data: bytes) -> str:
        sha = sha256_bytes(data)
        atomic_write_bytes(self.root / check_rel_path(rel_path), data)
        self.files[rel_path] = sha
        return sha
