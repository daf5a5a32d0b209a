"""A mesh file's own materials, per part: OBJ/MTL, glTF 2.0 PBR and vertex colours (no Mitsuba).

:func:`mesh_parts` splits a mesh file into the parts trimesh loads (an OBJ is split per
``usemtl`` material, a glTF per primitive), in the same order as
:func:`scenegen.assets.shapes.load_mesh` concatenates them, so part ``i`` is a contiguous run of
the loaded mesh's vertices and faces. Each part carries an :class:`AssetMaterial`, a neutral
record in linear RGB that :mod:`scenegen.render.asset_materials` turns into a Mitsuba BSDF.

What is read:

* MTL (parsed here, line by line, with every map name checked by
  :mod:`scenegen.assets.asset_refs`): ``Kd`` (diffuse, linear RGB), ``map_Kd`` (sRGB image,
  multiplied by Kd as the MTL format says), ``Ks`` and ``Ns`` (Blinn-Phong specular colour and
  exponent), ``d`` (or ``Tr`` = 1 - d) and ``map_d`` (opacity), ``map_Bump``/``bump`` (height
  map, ``-bm`` scale), ``norm`` (tangent-space normal map), ``Ke``/``map_Ke`` (emission).
* glTF 2.0 (as trimesh loads it): ``baseColorFactor`` x ``baseColorTexture`` (sRGB), its alpha,
  ``metallicFactor``/``roughnessFactor`` x ``metallicRoughnessTexture`` (B = metallic,
  G = roughness, linear), ``normalTexture`` (linear), ``emissiveFactor`` x ``emissiveTexture``
  (sRGB), ``alphaMode``/``alphaCutoff``, ``doubleSided``.
* Vertex colours (PLY, OBJ ``v x y z r g b``, glTF ``COLOR_0`` without a material): sRGB-encoded
  8-bit values as trimesh stores them, decoded to linear reflectance.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh

from scenegen.assets.asset_refs import checked_ref, mtllib_names
from scenegen.assets.shapes import uv_from_trimesh
from scenegen.assets.texture_files import load_data_image, load_image
from scenegen.geometry.color import linear_from_srgb

ALPHA_MODES = ("opaque", "mask", "blend")


@dataclass(frozen=True, eq=False)
class AssetMaterial:
    """A material read from a mesh file; colours linear RGB in [0, 1], images float32."""

    name: str
    source: str  # 'mtl', 'gltf' or 'vertex_colors'
    base_color: tuple = (0.5, 0.5, 0.5)  # diffuse / base colour (multiplies base_texture)
    base_texture: np.ndarray | None = None  # (H, W, 3) linear
    opacity: float = 1.0  # MTL d, glTF baseColorFactor alpha (multiplies opacity_texture)
    opacity_texture: np.ndarray | None = None  # (H, W) in [0, 1]
    alpha_mode: str = "opaque"  # one of ALPHA_MODES
    alpha_cutoff: float = 0.5  # 'mask': opaque where opacity >= cutoff
    specular: tuple | None = None  # MTL Ks (None or zero: no specular lobe)
    shininess: float | None = None  # MTL Ns (Blinn-Phong exponent)
    metallic: float | None = None  # glTF metallicFactor (None: not a PBR material)
    roughness: float | None = None  # glTF roughnessFactor (perceptual, alpha = roughness^2)
    metallic_roughness_texture: np.ndarray | None = None  # (H, W, 3) linear, B metallic, G roughness
    normal_texture: np.ndarray | None = None  # (H, W, 3) in [0, 1], tangent space, +y up the image
    bump_texture: np.ndarray | None = None  # (H, W) heights in [0, 1]
    bump_scale: float = 1.0
    emissive: tuple = (0.0, 0.0, 0.0)  # linear RGB radiance factor (multiplies emissive_texture)
    emissive_texture: np.ndarray | None = None  # (H, W, 3) linear
    double_sided: bool = False
    vertex_colors: np.ndarray | None = field(default=None)  # (V, 3) linear, per part vertex


@dataclass(frozen=True, eq=False)
class MeshPart:
    """One part of a mesh file: its vertex and face runs in the loaded mesh, UVs, material."""

    vertex_start: int
    vertex_count: int
    face_start: int
    face_count: int
    uv: np.ndarray | None  # (vertex_count, 2) in the project's convention, or None
    material: AssetMaterial | None  # None: the file gives this part no material


def _texture_srgb(img) -> np.ndarray | None:
    """A PIL image of colour (sRGB) -> (H, W, 4) linear RGB + linear alpha."""
    if img is None:
        return None
    a = np.asarray(img.convert("RGBA"), dtype=np.float64) / 255.0
    out = a.copy()
    out[..., :3] = linear_from_srgb(a[..., :3])
    return out.astype(np.float32)


def _texture_linear(img) -> np.ndarray | None:
    if img is None:
        return None
    return (np.asarray(img.convert("RGB"), dtype=np.float64) / 255.0).astype(np.float32)


def _rgb_factor(v, n: int = 3, default=1.0) -> np.ndarray:
    if v is None:
        return np.full(n, default)
    a = np.asarray(v, dtype=np.float64).ravel()
    return a / 255.0 if a.dtype.kind in "ui" or a.max(initial=0) > 1.0 else a


def gltf_material(mat, name: str) -> AssetMaterial:
    """An :class:`AssetMaterial` from trimesh's ``PBRMaterial`` (factors as glTF stores them:
    base colour and emissive factors are linear)."""
    base = _rgb_factor(mat.baseColorFactor, 4)
    tex = _texture_srgb(mat.baseColorTexture)
    emis_tex = _texture_srgb(mat.emissiveTexture)
    mode = (mat.alphaMode or "OPAQUE").lower()
    return AssetMaterial(
        name=name, source="gltf", base_color=tuple(base[:3]),
        base_texture=None if tex is None else tex[..., :3], opacity=float(base[3]),
        opacity_texture=None if tex is None or mode == "opaque" else tex[..., 3],
        alpha_mode=mode if mode in ALPHA_MODES else "opaque",
        alpha_cutoff=0.5 if mat.alphaCutoff is None else float(mat.alphaCutoff),
        metallic=1.0 if mat.metallicFactor is None else float(mat.metallicFactor),
        roughness=1.0 if mat.roughnessFactor is None else float(mat.roughnessFactor),
        metallic_roughness_texture=_texture_linear(mat.metallicRoughnessTexture),
        normal_texture=_texture_linear(mat.normalTexture),
        emissive=tuple(_rgb_factor(mat.emissiveFactor, 3, 0.0)[:3]),
        emissive_texture=None if emis_tex is None else emis_tex[..., :3],
        double_sided=bool(mat.doubleSided))


def parse_mtl(mtl: Path, asset_dir: Path, within: Path | None = None) -> dict[str, AssetMaterial]:
    """Every material of an MTL file, by name (maps resolved against ``asset_dir``, checked
    inside ``within``, default ``asset_dir``)."""
    raw: dict[str, dict] = {}
    cur = None
    with open(mtl, "r", encoding="utf-8", errors="replace") as fh:
        for n, line in enumerate(fh, start=1):
            parts = line.split("#", 1)[0].split()
            if not parts:
                continue
            key, args = parts[0], parts[1:]
            if key == "newmtl":
                cur = raw.setdefault(" ".join(args), {})
                continue
            if cur is None:
                continue
            k = key.lower()
            if k in ("kd", "ks", "ke") and args:
                vals = [float(x) for x in args[:3]]
                cur[k] = tuple(vals * 3 if len(vals) == 1 else vals)
            elif k in ("ns", "d", "tr") and args:
                cur[k] = float(args[0])
            elif k in ("map_kd", "map_d", "map_bump", "bump", "norm", "map_ke") and args:
                cur[k] = checked_ref(args[-1], asset_dir, mtl, n, key, within).path
                if k in ("map_bump", "bump") and "-bm" in args:
                    cur["bm"] = float(args[args.index("-bm") + 1])
    return {name: _mtl_material(name, r) for name, r in raw.items()}


def _grey(path: Path) -> np.ndarray:
    """A map read as data (not colour): linear values in [0, 1], (H, W) of the first channel."""
    return load_data_image(path)[..., 0]


def _mtl_material(name: str, r: dict) -> AssetMaterial:
    opacity = r["d"] if "d" in r else (1.0 - r["tr"] if "tr" in r else 1.0)
    ks = r.get("ks")
    return AssetMaterial(
        name=name, source="mtl", base_color=r.get("kd", (0.8, 0.8, 0.8)),
        base_texture=load_image(r["map_kd"]) if "map_kd" in r else None,
        opacity=float(opacity), opacity_texture=_grey(r["map_d"]) if "map_d" in r else None,
        alpha_mode="blend" if opacity < 1.0 or "map_d" in r else "opaque",
        specular=ks if ks is not None and max(ks) > 0 else None, shininess=r.get("ns"),
        normal_texture=load_data_image(r["norm"]) if "norm" in r else None,
        bump_texture=_grey(r.get("map_bump") or r["bump"]) if ("map_bump" in r or "bump" in r) else None,
        bump_scale=r.get("bm", 1.0), emissive=r.get("ke", (0.0, 0.0, 0.0)),
        emissive_texture=load_image(r["map_ke"]) if "map_ke" in r else None)


def _obj_materials(path: Path, within: Path | None = None) -> dict[str, AssetMaterial]:
    out: dict[str, AssetMaterial] = {}
    with open(path, "r", encoding="utf-8", errors="replace") as fh:
        for n, line in enumerate(fh, start=1):
            parts = line.split("#", 1)[0].split()
            if parts[:1] == ["mtllib"]:
                for written in mtllib_names(" ".join(parts[1:]), path.parent):
                    mtl = checked_ref(written, path.parent, path, n, "mtllib", within).path
                    out.update(parse_mtl(mtl, path.parent, within))
    return out


def _vertex_colors(visual) -> np.ndarray | None:
    if not isinstance(visual, trimesh.visual.ColorVisuals) or visual.kind != "vertex":
        return None
    c = np.asarray(visual.vertex_colors, dtype=np.float64)[:, :3] / 255.0
    return linear_from_srgb(c).astype(np.float32)


def mesh_parts(path, within: Path | None = None) -> list[MeshPart]:
    """The parts of a mesh file with their own materials (see the module docstring); the files
    it names must lie inside ``within`` (default its folder)."""
    path = Path(path)
    mtl = _obj_materials(path, within) if path.suffix.lower() == ".obj" else {}
    scene = trimesh.load_scene(str(path), process=False)
    parts, v0, f0 = [], 0, 0
    for node in scene.graph.nodes_geometry:  # the order of shapes.load_mesh
        _, gname = scene.graph[node]
        g = scene.geometry[gname]
        if not isinstance(g, trimesh.Trimesh) or len(g.faces) == 0:
            continue
        vis = g.visual
        uv = None
        if isinstance(vis, trimesh.visual.TextureVisuals) and vis.uv is not None \
                and len(vis.uv) == len(g.vertices):
            uv = uv_from_trimesh(vis.uv)
        mat = getattr(vis, "material", None)
        am = None
        if isinstance(mat, trimesh.visual.material.PBRMaterial):
            am = gltf_material(mat, getattr(mat, "name", None) or gname)
        elif mat is not None and getattr(mat, "name", None) in mtl:
            am = mtl[mat.name]
        colors = _vertex_colors(vis)
        if colors is not None:
            am = AssetMaterial(name=f"{gname} vertex colours", source="vertex_colors",
                               base_color=(1.0, 1.0, 1.0), vertex_colors=colors)
        parts.append(MeshPart(v0, len(g.vertices), f0, len(g.faces), uv, am))
        v0 += len(g.vertices)
        f0 += len(g.faces)
    return parts
