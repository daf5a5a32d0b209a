"""One writer per dataset folder: an advisory lock file, ``<folder>/.scenegen.lock``.

:class:`~scenegen.dataset.writer.DatasetWriter` takes it before it looks at the folder (before a
resumed run removes stale temporary files, which would otherwise delete a live writer's) and
removes it when it closes. The file holds the owner's pid, host and start time, so a second
writer's error says who holds the folder.

The lock itself is the kernel's ``flock`` on the open file: it is released when its owner exits
in any way (kill -9 included), so a lock file left by a dead process is *stale*: the next writer
takes it over (:attr:`DatasetLock.taken_over` records whose it was). Where ``flock`` is not
available (some network file systems) the file is created exclusively instead, and a lock is
stale when its pid is no longer running on this host; a lock held from another host is then
reported, never broken.

The name starts with a dot, so no dataset file can have it (:func:`scenegen.dataset.layout.
check_rel_path` refuses hidden names); ``verify`` reports it as unexpected while a run is active
or after a crash, and a finished run leaves none.
"""
from __future__ import annotations

import errno
import json
import os
import socket
import time
from pathlib import Path

from scenegen.dataset.errors import DatasetError

try:
    import fcntl
except ImportError:  # Windows: the exclusive-create fallback only
    fcntl = None

LOCK_NAME = ".scenegen.lock"
#: errno values meaning "this file system does not do flock".
_NO_FLOCK = {errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EINVAL, errno.ENOSYS}


class DatasetLockedError(DatasetError):
    """The dataset folder is being written by another live process."""


def owner_record() -> dict:
    """Who takes a lock: this process."""
    return {"pid": os.getpid(), "host": socket.gethostname(),
            "since": time.strftime("%Y-%m-%dT%H:%M:%S%z")}


def describe_owner(info: dict | None) -> str:
    if not info:
        return "an unknown process (the lock file is empty or unreadable)"
    return (f"pid {info.get('pid', '?')} on host {info.get('host', '?')}"
            + (f" since {info['since']}" if info.get("since") else ""))


def _read_info(fd: int) -> dict | None:
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        data = os.read(fd, 4096)
        info = json.loads(data.decode("utf-8")) if data.strip() else None
        return info if isinstance(info, dict) else None
    except (OSError, ValueError):
        return None


def _write_info(fd: int, info: dict) -> None:
    os.lseek(fd, 0, os.SEEK_SET)
    os.ftruncate(fd, 0)
    os.write(fd, (json.dumps(info, sort_keys=True) + "\n").encode("utf-8"))
    os.fsync(fd)


def _pid_alive(pid) -> bool:
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except (PermissionError, ValueError, TypeError, OverflowError):
        return True  # exists (another user's), or unreadable: assume alive
    return True


class DatasetLock:
    """A held lock on a dataset folder; :meth:`release` (idempotent) removes it."""

    def __init__(self, path: Path, fd: int | None, taken_over: dict | None):
        self.path = path
        self._fd = fd
        self.taken_over = taken_over  # the stale owner's record, when the lock was taken over
        #: True when :meth:`acquire` made the folder itself (``mkdir`` succeeded here): only then
        #: may its owner remove the folder again (:meth:`DatasetWriter.discard
        #: <scenegen.dataset.writer.DatasetWriter.discard>`). Deciding "fresh" by looking before
        #: the lock is taken would let a refused second writer delete the live writer's folder.
        self.created_root = False

    @classmethod
    def acquire(cls, root) -> "DatasetLock":
        """Take the lock of folder ``root`` (created if absent). DatasetLockedError naming the
        owner when a live process holds it; OSError (read-only, full disk) when the lock file
        cannot be written."""
        root = Path(root)
        try:
            root.mkdir(parents=True)  # atomic: of two processes, exactly one creates the folder
            created = True
        except FileExistsError:
            created = False
        path = root / LOCK_NAME
        lock = None
        if fcntl is not None:
            for _ in range(20):  # retried only when an owner removed the file under us
                lock = cls._try_flock(root, path)
                if lock is not None:
                    break
        if lock is None:
            lock = cls._exclusive(root, path)
        lock.created_root = created
        return lock

    @classmethod
    def _try_flock(cls, root: Path, path: Path) -> "DatasetLock | None":
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise DatasetLockedError(
                    f"{root} is being written by another scenegen run ({describe_owner(_read_info(fd))}); "
                    "wait for it to finish, or write to another folder") from None
            except OSError as e:
                if e.errno in _NO_FLOCK:
                    os.close(fd)
                    return cls._exclusive(root, path)
                raise
            try:
                same = os.stat(path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # the previous owner removed the file between our open and flock
                os.close(fd)
                return None
            stale = _read_info(fd)
            _write_info(fd, owner_record())
            return cls(path, fd, stale)
        except BaseException:
            try:
                os.close(fd)
            except OSError:
                pass
            raise

    @classmethod
    def _exclusive(cls, root: Path, path: Path) -> "DatasetLock":
        """The fallback without flock: an exclusively created file; stale when its pid is gone."""
        taken_over = None
        for _ in range(2):
            try:
                fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                fd = os.open(path, os.O_RDONLY)
                info = _read_info(fd)
                os.close(fd)
                if info and info.get("host") == socket.gethostname() and not _pid_alive(info.get("pid")):
                    path.unlink(missing_ok=True)  # stale: its process is gone
                    taken_over = info
                    continue
                raise DatasetLockedError(
                    f"{root} is being written by another scenegen run ({describe_owner(info)}); wait for it "
                    f"to finish, or write to another folder (if that run is gone, delete {path})") from None
            try:
                _write_info(fd, owner_record())
            finally:
                os.close(fd)
            return cls(path, None, taken_over)
        raise DatasetLockedError(f"{root}: could not take the lock {path}")

    def release(self) -> None:
        if self.path is None:
            return
        try:
            self.path.unlink(missing_ok=True)  # while still holding it: a waiter sees a new inode
        except OSError:
            pass
        if self._fd is not None:
            try:
                os.close(self._fd)
            except OSError:
                pass
        self.path, self._fd = None, None

    def __del__(self):  # a writer dropped without close() (e.g. its constructor raised)
        self.release()
