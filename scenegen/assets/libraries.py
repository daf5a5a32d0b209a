"""Asset libraries people already have on disk: a folder of meshes in a known layout, one
registry entry per layout (relative path pattern, axis and unit conventions), and the checked
path of one model.

A library model is named by its id (``02958343/1a0bc9ab92c915167ae33d942430658c`` in ShapeNet,
``Android_Figure_Panda`` in Google Scanned Objects, a uid in an Objaverse-style folder). Every path
built from an id is checked before anything is opened: the id is made of plain names (no ``..``,
``.``, empty part, absolute path, URL, backslash or NUL), has the layout's number of parts, and
the file it names lies inside the library root once links are resolved and exists
(:func:`scenegen.assets.asset_refs.checked_ref`). A bad id raises :class:`LibraryError`.
No spec import: the spec parser and the Python API call these.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from scenegen.assets.asset_refs import AssetFileError, AssetScope, checked_ref

#: One part of an id: letters, digits and ``_ - . +`` (not starting with a dot).
_ID_PART = re.compile(r"^[A-Za-z0-9_+-][A-Za-z0-9_.+-]*$")


class LibraryError(ValueError):
    """A library reference that cannot be used; ``key`` is the spec key at fault ('id', 'root',
    'category', 'pick')."""

    def __init__(self, message: str, key: str):
        super().__init__(message)
        self.key = key


@dataclass(frozen=True)
class Layout:
    """A library layout: where a model's mesh file lies and how it is to be read."""

    name: str
    pattern: str  # the mesh file relative to the root; '{id}' is the model id
    id_parts: int  # '/'-separated parts of an id (ShapeNet: synset/model)
    up_axis: str  # the file's up axis ('y' or 'z'), as in scenegen.geometry.conventions
    front: str  # the files' front direction, as stated by the library (documentation)
    units: str  # the files' length unit (documentation)
    asset_up: int  # the asset folder (files the mesh may name): the mesh path's parents[asset_up]
    source: str  # where the conventions are stated
    search: tuple[str, ...] = ()  # folders of the asset folder where names not found are looked up


LAYOUTS = {
    "shapenet": Layout(
        "shapenet", "{id}/models/model_normalized.obj", 2, "y", "-z (file axes)",
        "normalised: bounding-box diagonal 1, not centred", 1,
        "ShapeNetCore v2 README: 'up direction is the +Y axis, and the front is the -Z axis'"),
    "shapenet_v1": Layout(
        "shapenet_v1", "{id}/model.obj", 2, "y", "+x (file axes)",
        "normalised: fits a unit cube centred at the origin", 0,
        "ShapeNetCore v1 README: 'up direction is the +Y axis, and the front is the +X axis'"),
    "gso": Layout(
        "gso", "{id}/meshes/model.obj", 1, "z", "none (scans)", "metres", 1,
        "Google Scanned Objects: Z-up, metres (meshes/model.obj, materials/textures/texture.png)",
        ("materials/textures",)),  # its model.mtl names 'texture.png', kept in materials/textures/
    "objaverse": Layout(
        "objaverse", "{id}.glb", 1, "y", "+z (glTF)", "as authored (glTF says metres)", 0,
        "glTF 2.0 'Coordinate System and Units': +Y up, +Z front, metres"),
}
LIBRARY_LAYOUTS = tuple(LAYOUTS)


def check_id(layout: Layout, model_id: str) -> None:
    """LibraryError for an id that is not ``id_parts`` plain names joined by '/'."""
    if not isinstance(model_id, str) or not model_id:
        raise LibraryError(f"expected a model id of the {layout.name} layout, got {model_id!r}", "id")
    parts = model_id.split("/")
    bad = [p for p in parts if not _ID_PART.match(p)]
    if bad or "\\" in model_id:
        raise LibraryError(f"{model_id!r}: expected plain names joined by '/' (letters, digits, _ - . +; "
                           f"no '..', absolute path, URL or backslash), got the part {bad[0] if bad else model_id!r}",
                           "id")
    if len(parts) != layout.id_parts:
        shape = "<synset>/<model_id>" if layout.id_parts == 2 else "<name>"
        raise LibraryError(f"{model_id!r}: a {layout.name} id is {shape} ({layout.id_parts} part"
                           f"{'s' if layout.id_parts > 1 else ''}), got {len(parts)}", "id")


@dataclass(frozen=True)
class LibraryFile:
    path: Path  # absolute, resolved, inside the root
    relative: str  # the mesh file relative to the root (posix)
    asset_dir: AssetScope  # where the mesh's own files (MTL, textures) must lie and are looked up


def library_file(layout_name: str, root: Path, model_id: str) -> LibraryFile:
    """The checked mesh file of ``model_id`` in the library at ``root`` (an existing folder)."""
    layout = LAYOUTS[layout_name]
    root = Path(root)
    if not root.is_dir():
        raise LibraryError(f"{str(root)!r}: expected the library's folder, "
                           f"{'a file' if root.exists() else 'no such folder'}", "root")
    check_id(layout, model_id)
    relative = layout.pattern.format(id=model_id)
    try:
        ref = checked_ref(relative, root, root, None, "id")
    except AssetFileError as e:
        raise LibraryError(f"{model_id!r} ({relative}): {e.message.split(': ', 1)[-1]}".replace(
            "asset's folder", "library root"), "id") from None
    return LibraryFile(ref.path, relative, asset_dir_of(ref.path, layout_name))


def asset_dir_of(mesh_path: Path, layout_name: str | None) -> AssetScope:
    """Where the files named inside a mesh may lie: the mesh's own folder, or a library model's
    folder (ShapeNet v2 names ``../images/...`` from ``models/``) with its layout's search folders."""
    if layout_name is None:
        return AssetScope(Path(mesh_path).parent)
    layout = LAYOUTS[layout_name]
    root = Path(mesh_path).parents[layout.asset_up]
    return AssetScope(root, tuple(root / d for d in layout.search))


def category_ids(layout_name: str, root: Path, category: str) -> tuple[str, ...]:
    """The ids of the models of ``category`` (the first id part: a ShapeNet synset) whose mesh
    file exists, sorted (so a pick does not depend on the file system's listing order)."""
    layout = LAYOUTS[layout_name]
    if layout.id_parts != 2:
        raise LibraryError(f"the {layout.name} layout has no categories (its ids are single names); "
                           "give an 'id'", "category")
    check_id(LAYOUTS["gso"], category)  # one plain name
    folder = Path(root) / category
    if not folder.is_dir():
        raise LibraryError(f"no category {category!r} in {str(root)!r}", "category")
    ids = sorted(f"{category}/{d.name}" for d in folder.iterdir()
                 if _ID_PART.match(d.name) and (Path(root) / layout.pattern.format(id=f"{category}/{d.name}")).is_file())
    if not ids:
        raise LibraryError(f"category {category!r} of {str(root)!r} holds no model "
                           f"({layout.pattern.format(id='<synset>/<model_id>')})", "category")
    return tuple(ids)


def pick_id(layout_name: str, root: Path, category: str, pick: int | None, seed: int) -> str:
    """Model ``pick`` (None: the first, 0) of a seeded permutation of the category's sorted ids:
    picks 0 .. N-1 with one seed are N distinct models."""
    pick = 0 if pick is None else pick
    ids = category_ids(layout_name, root, category)
    if not 0 <= pick < len(ids):
        raise LibraryError(f"pick {pick}: category {category!r} holds {len(ids)} model{'s' * (len(ids) != 1)} "
                           f"(expected 0 <= pick < {len(ids)})", "pick")
    order = np.random.default_rng(seed).permutation(len(ids))
    return ids[int(order[pick])]


def mesh_within(geometry) -> AssetScope:
    """The folder the files named inside a spec mesh may lie in (read by attribute: ``path`` and
    ``library``, so no spec import)."""
    library = getattr(geometry, "library", None)
    return asset_dir_of(geometry.path, None if library is None else library.layout)
