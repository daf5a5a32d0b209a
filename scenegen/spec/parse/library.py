"""``mesh: {library: shapenet, root: ..., id: ...}``: a model of an asset library folder
(:mod:`scenegen.assets.libraries`), by id or picked by seed from a category, turned into the mesh
file it names; every path built from the id checked, errors at the spec's file:line."""
from __future__ import annotations

from pathlib import Path

from scenegen.assets.libraries import LAYOUTS, LIBRARY_LAYOUTS, LibraryError, library_file, pick_id
from scenegen.located_yaml import Fields, Node
from scenegen.spec.model import geometry as mg
from scenegen.spec.parse.context import ParseContext

LIBRARY_KEYS = ("library", "root", "id", "category", "pick", "seed", "up_axis", "scale")


def _root(node: Node) -> tuple[Path, str]:
    text = node.as_str("the library's folder (a path)")
    if "\x00" in text or not text.strip():
        raise node.error(f"expected the library's folder (a path), got {text!r}")
    p = Path(text).expanduser()
    try:
        return (p if p.is_absolute() else node.doc.base_dir / p).resolve(), text
    except (OSError, RuntimeError) as e:  # a symlink loop, a name too long
        raise node.error(f"cannot resolve the path {text!r}: {e}") from None


def library_model(f: Fields, node: Node, ctx: ParseContext):
    """(LibraryFile, LibraryRef) of a `mesh:` mapping with `library:`."""
    f.check(required=("library", "root"), optional=LIBRARY_KEYS)
    layout = f.get("library").as_enum(LIBRARY_LAYOUTS, "library layout")
    root, root_written = _root(f.get("root"))
    which = f.one_of(("id", "category"))
    for k in ("pick", "seed"):
        if k in f and which == "id":
            raise f.get(k).error(f"{k!r} goes with 'category' (a pick by seed), not with 'id'")
    try:
        if which == "id":
            model_id = f.get("id").as_str("a model id")
        else:
            category = f.get("category").as_str("a category (a ShapeNet synset id)")
            pick = f.get("pick").as_int("a pick index", lo=0) if "pick" in f else None
            seed = (f.get("seed").as_int("a seed", lo=0, hi=2**32 - 1) if "seed" in f
                    else ctx.seed_for(f"library.{layout}.{category}"))  # shared: picks 0..N-1 differ
            model_id = pick_id(layout, root, category, pick, seed)
        lib = library_file(layout, root, model_id)
    except LibraryError as e:
        raise (f.get(e.key) or f.get(which) or node).error(str(e)) from None
    ref = mg.LibraryRef(layout=layout, root=root_written, id=model_id)
    return lib, ref, f"{root_written.rstrip('/')}/{lib.relative}", LAYOUTS[layout].up_axis
