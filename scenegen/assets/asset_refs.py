"""The files a mesh file names (an OBJ's MTL libraries and their texture maps, a glTF's buffers
and images), checked before anything is loaded, and whether the file carries materials of its own.

Every name read from an asset file is checked: it must be a relative path (no drive, no URL
scheme), it must stay inside the asset's own folder once resolved (``..`` and links that leave it
are refused) and it must be an existing file. A bad name raises :class:`AssetFileError` naming the
file and line it was read from (``chair.mtl:7: map_Kd '../x.png' leaves the asset's folder ...``).
``data:`` URIs of a glTF are embedded data, not files.
"""
from __future__ import annotations

import json
import math
import re
import struct
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import unquote

#: MTL statements whose last argument is a file (map options such as ``-bm 0.5`` come before it).
MTL_MAP_KEYS = ("map_kd", "map_ks", "map_ns", "map_d", "map_bump", "bump", "norm", "map_ke",
                "disp", "decal", "refl", "map_ka")
_URI_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")


class AssetFileError(ValueError):
    """A name read from an asset file that cannot be used: ``file`` and 1-based ``line`` (or None)."""

    def __init__(self, message: str, file: Path, line: int | None):
        super().__init__(message)
        self.message, self.file, self.line = message, file, line

    def __str__(self) -> str:
        head = f"{self.file}:{self.line}" if self.line is not None else str(self.file)
        return f"{head}: {self.message}"


@dataclass(frozen=True)
class AssetRef:
    """One file named inside an asset file."""

    path: Path  # absolute, resolved, inside the asset's folder
    written: str  # the name as written in the asset file
    source: Path  # the file that names it (the mesh or its MTL)
    line: int | None  # 1-based line of the name in ``source`` (None inside a .glb)
    key: str  # the statement or glTF field, e.g. 'mtllib', 'map_Kd', 'images[0].uri'


@dataclass(frozen=True)
class AssetScan:
    """What :func:`scan_mesh_file` found."""

    refs: tuple[AssetRef, ...]  # in the order read
    materials: tuple[str, ...]  # names (or 'material <i>') of the file's own materials
    vertex_colors: bool  # the file stores per-vertex colours

    @property
    def has_materials(self) -> bool:
        return bool(self.materials) or self.vertex_colors


@dataclass(frozen=True)
class AssetScope:
    """Where the files a mesh names may lie: inside ``root``; a name not found where it is
    relative to is also looked up in the ``search`` folders (Google Scanned Objects' MTL names
    ``texture.png``, which lies in ``materials/textures/``)."""

    root: Path
    search: tuple[Path, ...] = ()


def checked_ref(written: str, asset_dir: Path, source: Path, line: int | None, key: str,
                within: "Path | AssetScope | None" = None) -> AssetRef:
    """A file name read from ``source``, relative to ``asset_dir``, checked to lie inside
    ``within`` (default ``asset_dir``; a library model's folder or scope,
    :mod:`scenegen.assets.libraries`)."""
    where = lambda msg: AssetFileError(f"{key} {written!r}: {msg}", source, line)
    if not written.strip():
        raise where("expected a file name, got nothing")
    if _URI_SCHEME.match(written) or written.startswith(("/", "\\")) or Path(written).is_absolute():
        raise where("expected a path relative to the asset's folder (no absolute path or URL)")
    scope = within if isinstance(within, AssetScope) else AssetScope(asset_dir if within is None else within)
    root = scope.root.resolve()
    full = (asset_dir.resolve() / written).resolve()
    if not full.is_file():
        full = next((c for c in ((d / written).resolve() for d in scope.search) if c.is_file()), full)
    if full != root and root not in full.parents:
        raise where(f"leaves the asset's folder {str(root)!r}; asset files may only name files "
                    "inside it")
    if not full.is_file():
        raise where(f"file not found (looked for {full})")
    return AssetRef(full, written, source, line, key)


def scan_mesh_file(path: Path, within: Path | None = None) -> AssetScan:
    """The files named by a mesh file (checked: inside ``within``, default the mesh's folder) and
    its own materials; nothing for PLY/STL but vertex colours."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext == ".obj":
        return _scan_obj(path, within)
    if ext in (".gltf", ".glb"):
        return _scan_gltf(path)
    if ext == ".ply":
        return AssetScan((), (), _ply_has_colors(path))
    return AssetScan((), (), False)


def _lines(path: Path):
    with open(path, "r", encoding="utf-8", errors="replace") as fh:
        for n, raw in enumerate(fh, start=1):
            line = raw.split("#", 1)[0].strip()
            if line:
                yield n, line


def _scan_obj(path: Path, within: Path | None = None) -> AssetScan:
    refs, names, colors = [], [], False
    for n, line in _lines(path):
        head, _, rest = line.partition(" ")
        if head == "mtllib":
            for written in mtllib_names(rest.strip(), path.parent):
                ref = checked_ref(written, path.parent, path, n, "mtllib", within)
                refs.append(ref)
                mtl_refs, mtl_names = scan_mtl(ref.path, path.parent, within)
                refs.extend(mtl_refs)
                names.extend(mtl_names)
        elif head == "v" and len(rest.split()) >= 6:
            colors = True
    return AssetScan(tuple(refs), tuple(names), colors)


def mtllib_names(rest: str, folder: Path) -> list[str]:
    """The MTL names of an ``mtllib`` line: one name with spaces if that file exists, else the
    whitespace-separated names."""
    if " " in rest and (folder / rest).is_file():
        return [rest]
    return rest.split()


#: MTL statements read as numbers: how many (1 or 3 for a colour; 1 for a scalar) and the range.
MTL_NUMBERS = {"kd": ((1, 3), 0.0, 1.0), "ks": ((1, 3), 0.0, 1.0), "ke": ((1, 3), 0.0, None),
               "ns": ((1,), 0.0, None), "d": ((1,), 0.0, 1.0), "tr": ((1,), 0.0, 1.0)}


def _check_numbers(key: str, args: list[str], mtl: Path, n: int) -> None:
    counts, lo, hi = MTL_NUMBERS[key.lower()]
    try:
        vals = [float(a) for a in args[:max(counts)]]
    except ValueError:
        vals = None
    bad = vals is None or len(vals) not in counts or not all(
        math.isfinite(v) and v >= lo and (hi is None or v <= hi) for v in vals)
    if bad:
        rng = f"in [{lo:g}, {hi:g}]" if hi is not None else f">= {lo:g}"
        raise AssetFileError(f"{key}: expected {' or '.join(map(str, counts))} number(s) {rng}, "
                             f"got {' '.join(args) or 'nothing'!r}", mtl, n)


def scan_mtl(mtl: Path, asset_dir: Path, within: Path | None = None) -> tuple[list[AssetRef], list[str]]:
    """(texture files named by an MTL file, checked; its material names in order); the numbers
    of Kd, Ks, Ke, Ns, d and Tr are checked too."""
    refs, names = [], []
    for n, line in _lines(mtl):
        parts = line.split()
        key = parts[0]
        if key == "newmtl":
            names.append(" ".join(parts[1:]))
        elif key.lower() in MTL_NUMBERS:
            _check_numbers(key, parts[1:], mtl, n)
        elif key.lower() in MTL_MAP_KEYS:
            if len(parts) < 2:
                raise AssetFileError(f"{key}: expected a file name", mtl, n)
            refs.append(checked_ref(parts[-1], asset_dir, mtl, n, key, within))
    return refs, names


def _gltf_json(path: Path) -> tuple[dict, str | None]:
    """(the glTF JSON, its text for line numbers or None for a .glb)."""
    data = path.read_bytes()
    try:
        if path.suffix.lower() == ".glb":
            if data[:4] != b"glTF" or len(data) < 20:
                raise ValueError("not a binary glTF (no 'glTF' header)")
            (length,) = struct.unpack_from("<I", data, 12)
            return json.loads(data[20:20 + length].decode("utf-8")), None
        text = data.decode("utf-8")
        return json.loads(text), text
    except (ValueError, UnicodeDecodeError) as e:
        raise AssetFileError(f"could not be read as glTF ({e})", path, None) from None
    except RecursionError:  # a hostile file: arrays or objects nested thousands deep
        raise AssetFileError("could not be read as glTF (invalid JSON: nested too deeply)", path, None) from None


def _line_of(text: str | None, needle: str) -> int | None:
    if text is None:
        return None
    i = text.find(json.dumps(needle))
    return None if i < 0 else text.count("\n", 0, i) + 1


#: Deepest glTF node hierarchy read. Why: trimesh resolves each node's transform along its path
#: from the root, in time growing with the square of the depth (measured: 4,000 levels 0.3 s,
#: 16,000 levels 4.4 s, 100,000 levels minutes); real assets (scenes, skeletons) nest tens deep.
MAX_GLTF_NODE_DEPTH = 1024


def _check_gltf_nodes(doc: dict, path: Path) -> None:
    """AssetFileError for a node hierarchy deeper than MAX_GLTF_NODE_DEPTH or not a forest (a
    node that is its own ancestor), walked without recursion."""
    nodes = doc.get("nodes") if isinstance(doc.get("nodes"), list) else []
    children = [n.get("children") if isinstance(n, dict) and isinstance(n.get("children"), list) else []
                for n in nodes]
    depth = [0] * len(nodes)
    stack = [(i, 1) for i in range(len(nodes))][::-1]
    while stack:
        i, d = stack.pop()
        if not (isinstance(i, int) and 0 <= i < len(nodes)) or depth[i] >= d:
            continue
        if d > MAX_GLTF_NODE_DEPTH:
            raise AssetFileError(f"nodes are nested more than {MAX_GLTF_NODE_DEPTH} levels deep (or a node is its "
                                 "own ancestor): expected a tree of nodes (MAX_GLTF_NODE_DEPTH)", path, None)
        depth[i] = d
        stack.extend((c, d + 1) for c in children[i])


def _scan_gltf(path: Path) -> AssetScan:
    doc, text = _gltf_json(path)
    if not isinstance(doc, dict):
        raise AssetFileError(f"could not be read as glTF (expected a JSON object, got {type(doc).__name__})",
                             path, None)
    _check_gltf_nodes(doc, path)
    refs = []
    for section in ("buffers", "images"):
        for i, item in enumerate(doc.get(section) or []):
            uri = item.get("uri") if isinstance(item, dict) else None
            if not isinstance(uri, str) or uri.startswith("data:"):
                continue
            refs.append(checked_ref(unquote(uri), path.parent, path, _line_of(text, uri),
                                    f"{section}[{i}].uri"))
    mats = tuple(m.get("name") or f"material {i}" if isinstance(m, dict) else f"material {i}"
                 for i, m in enumerate(doc.get("materials") or []))
    colors = any("COLOR_0" in (p.get("attributes") or {})
                 for mesh in doc.get("meshes") or [] for p in mesh.get("primitives") or [])
    return AssetScan(tuple(refs), mats, colors)


def _ply_has_colors(path: Path) -> bool:
    with open(path, "rb") as fh:
        head = fh.read(4096).split(b"end_header", 1)[0].decode("ascii", errors="replace")
    return any(line.split()[-1:] in (["red"], ["r"], ["diffuse_red"])
               for line in head.splitlines() if line.startswith("property"))
