"""``pbr_set: {folder, name?, resolution?, disp_scale_m?}`` on a principled material: a PBR texture
set folder in Poly Haven's naming (:mod:`scenegen.assets.pbr_sets`), found by listing the folder;
errors at the spec's file:line."""
from __future__ import annotations

from pathlib import Path

from scenegen.assets.pbr_sets import PbrSetError, SetMap, find_set
from scenegen.located_yaml import Node
from scenegen.spec.model import materials as mm
from scenegen.spec.parse.fields import check_keys, read_fields

#: Keys a material with a `pbr_set` cannot also have: the set gives them.
SET_GIVES = ("color", "texture", "normal_map", "bump_map")


def _pbr_map(m: SetMap | None) -> mm.PbrMap | None:
    if m is None:
        return None
    return mm.PbrMap(path=m.path, path_as_written=m.path.name, channel=m.channel, directx=m.directx)


def parse_pbr_set(node: Node, material: "Fields") -> tuple[mm.PbrSet, mm.Texture]:
    """(the set, its diff map as the material's texture)."""
    for k in SET_GIVES:
        if k in material:
            raise material.get(k).error(f"{k!r} and 'pbr_set' exclude each other: the texture set gives the "
                                        "base colour texture and the normal and bump maps")
    f = check_keys(node.as_mapping("a texture set (a mapping with 'folder')"), mm.PbrSet, required=("folder",))
    text = f.get("folder").as_str("the texture set's folder (a path)")
    if "\x00" in text or not text.strip():
        raise f.get("folder").error(f"expected the texture set's folder (a path), got {text!r}")
    p = Path(text).expanduser()
    folder = (p if p.is_absolute() else node.doc.base_dir / p).resolve()
    values = read_fields(f, mm.PbrSet)  # disp_scale_m; name and resolution are derived when absent
    for k in ("name", "resolution"):
        values[k] = f.get(k).as_str(f"the set's {k}") if k in f else None
    try:
        found = find_set(folder, values["name"], values["resolution"])
    except PbrSetError as e:
        raise (f.get(e.key) or f.get("folder")).error(str(e)) from None
    try:
        return pbr_records(found, text, values["disp_scale_m"], node.where)
    except PbrSetError as e:
        raise f.get("disp_scale_m").error(str(e)) from None


def pbr_records(found, folder_text: str, disp_scale_m: float | None, where=None) -> tuple[mm.PbrSet, mm.Texture]:
    """(the PbrSet record, the diff map as a texture) of a found set (also the Python API's)."""
    disp = None
    if disp_scale_m is not None:
        if found.disp is None:
            raise PbrSetError(f"set {found.name!r} ({found.resolution}) has no disp map", "disp_scale_m")
        disp = mm.PbrMap(path=found.disp, path_as_written=found.disp.name)
    pbr = mm.PbrSet(folder=folder_text, name=found.name, resolution=found.resolution, disp_scale_m=disp_scale_m,
                    roughness=_pbr_map(found.roughness), metallic=_pbr_map(found.metallic),
                    normal=_pbr_map(found.normal), disp=disp, where=where)
    texture = mm.Texture(kind="image", path=found.base_color,
                         path_as_written=f"{folder_text.rstrip('/')}/{found.base_color.name}", where=where)
    return pbr, texture
