"""Reading a YAML file's text: a size limit, UTF-8 only, and one clear error for everything else.

Every YAML file the tools read (scene specs, gate files) goes through :func:`read_source`, so a
binary file, a UTF-16 file, a directory, an unreadable or a huge file fails with one line naming
the file and what to do, never with a traceback.
"""
from __future__ import annotations

import codecs
from pathlib import Path

from scenegen.errors import SpecError

#: Largest YAML file read, in bytes (1 MiB). Why: YAML is composed in pure Python (PyYAML's
#: SafeLoader: the C loader keeps no source text for messages and cannot refuse deep nesting
#: before it recurses), in linear time but slowly: measured 0.06 MiB/s for a spec of 6,000
#: objects on the shared 2-core test machine (docs/reliability.md), several times faster on an
#: idle one. 1 MiB (about 7,000 objects or 20,000 explicit camera poses) validates in seconds to
#: tens of seconds; a 50 MB file would take many minutes. The largest bundled spec is 8 KB; many
#: views belong in generated placements (orbit, random, line, circle), large geometry in the mesh
#: files the spec names.
MAX_SOURCE_BYTES = 1024 * 1024

_BOMS = ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"),
         (codecs.BOM_UTF16_LE, "UTF-16"), (codecs.BOM_UTF16_BE, "UTF-16"))


def read_source(path, what: str = "YAML file") -> str:
    """The UTF-8 text of ``path`` (a UTF-8 byte-order mark is dropped). SpecError naming the file
    for a missing, unreadable, non-file, too large, binary or non-UTF-8 file."""
    p = Path(path)
    file = str(path)
    if "\x00" in file:
        raise SpecError(f"the {what} path contains a NUL byte", file=repr(file)[1:-1])
    try:
        if p.is_dir():
            raise SpecError(f"is a directory, expected a {what}", file=file)
        size = p.stat().st_size
        if size > MAX_SOURCE_BYTES:
            raise SpecError(f"the {what} is {size / 2**20:.1f} MiB; at most {MAX_SOURCE_BYTES // 2**20} MiB "
                            "are read (scenegen.located_yaml.source.MAX_SOURCE_BYTES: put large geometry "
                            "in mesh files the spec names)", file=file)
        data = p.read_bytes()
    except OSError as e:
        raise SpecError(f"cannot read the {what}: {e.strerror or e}", file=file) from None
    for bom, name in _BOMS:
        if data.startswith(bom):
            raise SpecError(f"the {what} is {name} encoded; save it as UTF-8", file=file)
    if data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8):]
    nul = data.find(b"\x00")
    if nul >= 0:
        raise SpecError(f"the {what} contains a NUL byte (is this a binary file?); expected UTF-8 text",
                        file=file, line=data.count(b"\n", 0, nul) + 1)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data.count(b"\n", 0, e.start) + 1
        raise SpecError(f"the {what} is not UTF-8 text (byte 0x{data[e.start]:02x} at offset {e.start}); "
                        "save it as UTF-8", file=file, line=line) from None
