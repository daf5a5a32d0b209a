"""Errors a user can fix: they name the file, the line and the field, and say what was expected.

The CLI prints ``str(err)`` and exits with status 2 (no traceback). Any stage that works from a
parsed spec (texture generation, mesh loading, rendering) can point back into the YAML through the
``where`` recorded on the spec's dataclasses: ``raise SpecError.at(obj.where, "mesh has no faces")``.
"""
from __future__ import annotations

import errno
from dataclasses import dataclass


#: The file name of a spec built in Python (scenegen.api): its YAML is generated, so a place in
#: it is named by its field only, never by a line of that YAML.
PYTHON_FILE = "<python>"


@dataclass(frozen=True)
class Where:
    """A place in a spec file: ``file`` as given by the user, ``line`` 1-based (or None),
    ``field`` a path such as ``objects[2].transform.rotation_deg`` (or None)."""

    file: str | None = None
    line: int | None = None
    field: str | None = None

    def __str__(self) -> str:
        line = None if self.file == PYTHON_FILE else self.line  # a line of generated YAML means nothing
        head = ":".join(str(p) for p in (self.file, line) if p is not None)
        return ": ".join(p for p in (head, self.field or "") if p)


class SpecError(Exception):
    """A scene spec that cannot be used, and why.

    ``str(err)`` reads ``scene.yaml:14: objects[2].transform.rotation_deg: expected 3 numbers
    (degrees), got 'abc'``; parts that are unknown are left out.
    """

    def __init__(self, message: str, *, file: str | None = None, line: int | None = None,
                 field: str | None = None):
        super().__init__(message)
        self.message = message  # what was expected (and what was found)
        self.file = file  # the spec file as the user named it, or '<string>'
        self.line = line  # 1-based line in that file, or None
        self.field = field  # field path, e.g. 'cameras.left.fx', or None

    @classmethod
    def at(cls, where: Where | None, message: str) -> "SpecError":
        """An error at a recorded place (``where`` may be None)."""
        w = where or Where()
        return cls(message, file=w.file, line=w.line, field=w.field)

    @property
    def where(self) -> Where:
        return Where(self.file, self.line, self.field)

    def __str__(self) -> str:
        prefix = str(self.where)
        return f"{prefix}: {self.message}" if prefix else self.message

    def __reduce__(self):  # keep the keyword fields through pickling (multiprocessing)
        return (_rebuild, (self.message, self.file, self.line, self.field))


def _rebuild(message, file, line, field):
    return SpecError(message, file=file, line=line, field=field)


#: What to do about an OSError, by errno name: disk full, read-only, no permission, too many files.
_OS_ADVICE = {"ENOSPC": "the disk is full: free space or write to another disk, then run again (a render "
                        "continues with --resume: everything already written is kept)",
              "EDQUOT": "the disk quota is exceeded: free space, then run again with --resume",
              "EROFS": "the file system is read-only: write to another folder (-o)",
              "EACCES": "permission denied: write to a folder you may write to, or fix its permissions",
              "EPERM": "operation not permitted: write to a folder you may write to",
              "EISDIR": "it is a directory: give a file name",
              "ENOTDIR": "a part of the path is a file, not a folder",
              "ENAMETOOLONG": "the path is too long",
              "EMFILE": "too many open files: raise the limit (ulimit -n) or use fewer workers"}


def os_error_message(e: OSError) -> str:
    """One line for an OSError: the file it concerns, what happened and what to do."""
    name = errno.errorcode.get(e.errno or 0, "")
    where = e.filename if e.filename is not None else "(no file named)"
    what = e.strerror or str(e)
    advice = _OS_ADVICE.get(name)
    return f"{where}: {what}" + (f": {advice}" if advice else "")
