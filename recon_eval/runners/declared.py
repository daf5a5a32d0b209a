"""Methods a user declares (:mod:`recon_eval.runners.external`): read from a methods file or
made from ``recon-eval run --command``, as :class:`recon_eval.runners.Method` entries that
:func:`recon_eval.runners.run_method` runs like the built-in ones.

Methods file (YAML through :mod:`scenegen.located_yaml`: duplicate keys refused, every error
names file:line: field)::

    version: 1
    methods:
      - {name: my-fmatrix, kind: fmatrix, command: "{python} examples/my_fmatrix.py {images} {out}"}
"""
from __future__ import annotations

import math
from pathlib import Path

from recon_eval.errors import InputError
from recon_eval.runners import FAULTS, METHODS, Method
from recon_eval.runners.external import CLI, KINDS, PIXELS, TIMEOUT_S, check_command, field_at
from scenegen.dataset.layout import MAX_NAME_LEN, NAME_RE
from scenegen.located_yaml.source import read_source
from scenegen.errors import SpecError
from scenegen.located_yaml import Document, Node


def external_method(name: str, kind: str, command: str, *, timeout_s: float = TIMEOUT_S, pixels: str | None = None,
                    description: str = "", declared_at: str = CLI) -> Method:
    """The :class:`Method` running ``command`` as an estimator of output ``kind``; InputError for a
    bad name, kind, command, timeout or pixels, naming the option (``declared_at`` :data:`CLI`:
    ``recon-eval run --command``) or ``declared_at: field`` (a methods file's FILE:LINE)."""
    if not isinstance(name, str) or not NAME_RE.match(name) or len(name) > MAX_NAME_LEN:
        raise InputError(f"{field_at(declared_at, 'name')}: {name!r}: expected 1-{MAX_NAME_LEN} letters, digits, "
                         f"'_', '.', '-' (starting with a letter or digit)")
    if name in METHODS or name in FAULTS:
        raise InputError(f"{field_at(declared_at, 'name')}: {name!r} is a built-in method; choose another name")
    check_command(command, kind, declared_at)
    if not (isinstance(timeout_s, (int, float)) and math.isfinite(timeout_s) and timeout_s > 0):
        raise InputError(f"{field_at(declared_at, 'timeout_s')}: expected a finite number of seconds > 0, got "
                         f"{timeout_s!r}")
    opts = {"name": name, "command": command, "kind": kind, "timeout_s": float(timeout_s), "declared_at": declared_at}
    if pixels is not None:
        if kind != "fmatrix" or pixels not in PIXELS:
            raise InputError(f"{field_at(declared_at, 'pixels')}: only for kind fmatrix, one of {', '.join(PIXELS)}")
        opts["pixels"] = pixels
    return Method(name, KINDS[kind].module, KINDS[kind].function, description or f"external {kind}: {command}",
                  tuple(sorted(opts.items())))


def load_methods(path) -> dict[str, Method]:
    """The methods of a methods file, by name."""
    p = Path(path)
    try:
        text = read_source(p, "methods file")  # size limit, UTF-8, one-line errors
        root = Document(text, str(p), p.parent).root
        doc = root.as_mapping("a mapping with 'version' and 'methods'").check(required=("version", "methods"))
        version = doc.req("version")
        if version.scalar() != 1 or isinstance(version.scalar(), bool):
            raise version.error(f"expected 1, got {version.describe()}")
        items = doc.req("methods").items("a non-empty list of methods")
        if not items:
            raise doc.req("methods").error("expected a non-empty list of methods")
        out = {}
        for item in items:
            m = _method(item)
            if m.name in out:
                raise item.error(f"name: {m.name!r} is declared twice")
            out[m.name] = m
        return out
    except SpecError as exc:  # the located-YAML layer's error, as recon_eval's bad input
        raise InputError(str(exc)) from None


def _method(item: Node) -> Method:
    f = item.as_mapping("a mapping (name, kind, command)").check(
        required=("name", "kind", "command"), optional=("timeout_s", "pixels", "description"))
    where = f"{item.doc.file}:{item.line}"
    kind = f.req("kind").as_enum(list(KINDS), "the output kind")
    timeout = f.get("timeout_s")
    t = TIMEOUT_S if timeout is None else timeout.as_float()
    if not (math.isfinite(t) and t > 0):
        raise timeout.error(f"expected a finite number of seconds > 0, got {timeout.describe()}")
    pixels = f.get("pixels")
    desc = f.get("description")
    try:
        return external_method(f.req("name").as_str(), kind, f.req("command").as_str(), timeout_s=t,
                               pixels=None if pixels is None else pixels.as_enum(list(PIXELS), "the pixels F is for"),
                               description="" if desc is None else desc.as_str(), declared_at=where)
    except InputError as exc:  # name the item's field path too
        raise item.error(str(exc).removeprefix(f"{where}: ")) from None
