"""PBR texture sets in Poly Haven's naming: one folder holding ``<name>_<map>_<resolution>.<ext>``
(``brick_wall_001_diff_1k.jpg``, ``..._nor_gl_1k.png``, ``..._rough_1k.jpg``, ``..._arm_1k.jpg``,
``..._disp_1k.png``), found by listing the folder (no name read from the spec becomes a path), and
what each map means:

* ``diff``: base colour, sRGB-encoded.
* ``rough``: perceptual roughness (Blender's Principled BSDF: GGX alpha = roughness^2), data.
* ``arm``: ambient occlusion (R, not read: the renderer computes occlusion), roughness (G),
  metallic (B), data; ``rough`` and ``metal`` files, when present, are taken before it.
* ``nor_gl`` / ``nor_dx``: tangent-space normal maps, OpenGL (+y up the image, what Mitsuba's
  ``normalmap`` and glTF expect) or DirectX (+y down: the green channel inverted). ``nor_gl`` is
  taken when present; ``nor_dx`` alone is converted (:func:`scenegen.geometry.conventions.
  opengl_from_directx_normal_map`).
* ``disp``: a height map, read as the bump map only when the spec gives its scale.

Only 8- and 16-bit PNG/JPEG maps are read (the texture loaders'); an EXR map is named in the error.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

#: The map kinds read, and the suffixes they may have.
MAP_KINDS = ("diff", "nor_gl", "nor_dx", "rough", "arm", "metal", "disp")
MAP_SUFFIXES = (".png", ".jpg", ".jpeg")
_FILE = re.compile(r"^(?P<name>.+?)_(?P<kind>diff|nor_gl|nor_dx|rough|arm|metal|disp)_(?P<res>[0-9]+k)"
                   r"\.(?P<ext>[A-Za-z]+)$")


class PbrSetError(ValueError):
    """A texture set that cannot be used; ``key`` is the spec key at fault."""

    def __init__(self, message: str, key: str):
        super().__init__(message)
        self.key = key


@dataclass(frozen=True)
class SetMap:
    path: Path  # absolute, inside the folder
    channel: int  # the channel holding the value (0 for a grey map; arm: 1 roughness, 2 metallic)
    directx: bool = False  # a DirectX normal map (green inverted against OpenGL)


@dataclass(frozen=True)
class FoundSet:
    name: str
    resolution: str
    base_color: Path
    roughness: SetMap | None
    metallic: SetMap | None
    normal: SetMap | None
    disp: Path | None


def _only(values: set[str], what: str, key: str, folder: Path) -> str:
    if len(values) != 1:
        raise PbrSetError(f"{str(folder)!r} holds the {what}s {', '.join(sorted(values))}; give '{key}'", key)
    return next(iter(values))


def find_set(folder: Path, name: str | None = None, resolution: str | None = None) -> FoundSet:
    """The maps of one set in ``folder`` (``name`` and ``resolution`` may be left out when the
    folder holds one of each); PbrSetError naming the key at fault."""
    folder = Path(folder)
    if not folder.is_dir():
        raise PbrSetError(f"{str(folder)!r}: expected the texture set's folder, "
                          f"{'a file' if folder.exists() else 'no such folder'}", "folder")
    found = [m for m in (_FILE.match(p.name) for p in sorted(folder.iterdir()) if p.is_file()) if m]
    if not found:
        raise PbrSetError(f"{str(folder)!r} holds no <name>_<map>_<resolution> file (maps: "
                          f"{', '.join(MAP_KINDS)})", "folder")
    name = name if name is not None else _only({m["name"] for m in found}, "set name", "name", folder)
    mine = [m for m in found if m["name"] == name]
    if not mine:
        raise PbrSetError(f"no set {name!r} in {str(folder)!r} (sets: {', '.join(sorted({m['name'] for m in found}))})",
                          "name")
    resolution = resolution if resolution is not None else _only({m["res"] for m in mine}, "resolution",
                                                                 "resolution", folder)
    maps = {m["kind"]: m for m in mine if m["res"] == resolution}
    if not maps:
        raise PbrSetError(f"set {name!r} has no {resolution} maps (has {', '.join(sorted({m['res'] for m in mine}))})",
                          "resolution")
    for kind, m in maps.items():
        if "." + m["ext"].lower() not in MAP_SUFFIXES:
            raise PbrSetError(f"{m.string}: a {m['ext']} map is not read; expected 8- or 16-bit "
                              f"{'/'.join(s[1:] for s in MAP_SUFFIXES)} (download the set as JPG or PNG)", "folder")
    if "diff" not in maps:
        raise PbrSetError(f"set {name!r} ({resolution}) has no diff map (the base colour)", "folder")
    path = lambda kind: folder.resolve() / maps[kind].string
    rough = SetMap(path("rough"), 0) if "rough" in maps else SetMap(path("arm"), 1) if "arm" in maps else None
    metal = SetMap(path("metal"), 0) if "metal" in maps else SetMap(path("arm"), 2) if "arm" in maps else None
    normal = (SetMap(path("nor_gl"), 0) if "nor_gl" in maps
              else SetMap(path("nor_dx"), 0, directx=True) if "nor_dx" in maps else None)
    return FoundSet(name, resolution, path("diff"), rough, metal, normal, path("disp") if "disp" in maps else None)
