"""Build a scene in Python and render it, without writing YAML (docs/python_api.md).

The scene is made of the frozen dataclasses :func:`scenegen.spec.load_spec` returns
(:mod:`scenegen.spec.model`: ``Sphere``, ``DiffuseMaterial``, ``ViewSet``, ``Orbit``, ...), and it
is validated by the YAML's own parser (:func:`scenegen.spec.check_spec`): a bad value is a
:class:`scenegen.errors.SpecError` naming its field (``<python>: objects[0].shape.radius:
expected metres > 0, got -1``). :func:`render` renders exactly what ``scenegen render`` renders
for :func:`to_yaml`'s text (the same bytes, the same spec hash).

    >>> from scenegen.api import Scene, camera, obj, render, Sphere, PointLight, ViewSet, Orbit
    >>> spec = Scene("ball", objects=[obj("ball", Sphere(radius=0.3))],            # doctest: +SKIP
    ...              lights=[PointLight(name="sun", position=(0, -2, 3), intensity=(20, 20, 20))],
    ...              cameras=[camera("cam", size=(160, 120), fov_deg=60)],
    ...              views=[ViewSet(name=None, camera="cam", rig=None, placement=Orbit(radius_m=2, count=4))])
    >>> render(spec, "out/ball", spp=16)                                            # doctest: +SKIP

This is the one module besides the command line that reaches into :mod:`scenegen.pipeline`.
"""
from __future__ import annotations

import dataclasses
import math
from os import PathLike
from pathlib import Path
from typing import Iterable, Mapping, get_args

from scenegen.assets.asset_refs import AssetFileError, scan_mesh_file
from scenegen.assets.libraries import LAYOUTS, LibraryError, check_id, library_file, mesh_within, pick_id
from scenegen.assets.pbr_sets import PbrSetError, find_set
from scenegen.errors import SpecError
from scenegen.geometry.conventions import mesh_up_axis
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.geometry.rotation import rotation_from_euler_deg
from scenegen.pipeline.run import RenderSummary, render_spec
from scenegen.spec import check_spec, same_spec, to_yaml
from scenegen.spec.model import (  # re-exported: the building blocks
    AreaLight, ArucoGridTarget, Blob, Box, CameraSpec, CharucoTarget, CheckerboardTarget, CirclePath,
    ConductorMaterial, ConstantLight, CrossviewSpec, Cylinder, DiffuseMaterial, EnvmapLight, LinePath,
    LookAt, LookAtList, MatchSetSpec, Orbit, Plane, PlasticMaterial, PointLight, PoseList, RandomPoses,
    RenderSettings, Rig, RigMember, SceneObject, SceneSpec, Sphere, SpotLight, Texture, Torus,
    Transform, ViewSet,
)
from scenegen.spec.model.geometry import AssetFile, LibraryRef, Mesh
from scenegen.spec.model.lights import Light
from scenegen.spec.model.materials import Material, PbrSet, PrincipledMaterial
from scenegen.spec.model.meta import frozen_mapping
from scenegen.spec.model.timeline import Animation, JointSpec, Keyframe, SequenceSpec, TrackSpec, TrajectorySpec
from scenegen.spec.model.views import TrajectoryPath
from scenegen.spec.parse.lights import default_light_name
from scenegen.spec.parse.pbr_set import pbr_records
from scenegen.spec.parse.rigs import stereo_rig
from scenegen.spec.parse.timeline import start_transform
from scenegen.spec.source import SpecSource
from scenegen.spec.to_yaml import PYTHON_FILE

__all__ = [
    "Scene", "camera", "obj", "render", "to_yaml", "check_spec", "same_spec", "SpecError",
    "mesh", "library_mesh", "library_picks", "pbr_set_material", "image_texture", "sequence", "keyframe", "trajectory", "stereo_rig",
    "Animation", "JointSpec", "Keyframe", "Mesh", "PrincipledMaterial", "SequenceSpec", "TrackSpec",
    "TrajectoryPath", "TrajectorySpec",
    "AreaLight", "ArucoGridTarget", "Blob", "Box", "CameraSpec", "CharucoTarget", "CheckerboardTarget",
    "CirclePath", "ConductorMaterial", "ConstantLight", "CrossviewSpec", "Cylinder", "DiffuseMaterial",
    "EnvmapLight", "LinePath", "LookAt", "LookAtList", "MatchSetSpec", "Orbit", "Plane", "PlasticMaterial",
    "PointLight", "PoseList", "RandomPoses", "RenderSettings", "Rig", "RigMember", "SceneObject", "SceneSpec",
    "Sphere", "SpotLight", "Texture", "Torus", "Transform", "ViewSet",
]


def mesh(path, *, up_axis: str | None = None) -> Mesh:
    """A mesh file (.ply, .obj, .glb, .gltf, .stl) as an object's geometry, with its own materials
    (OBJ/MTL, glTF PBR, vertex colours) unless :func:`obj` is given a ``material``. A relative
    ``path`` resolves against ``Scene(base_dir=...)``. ``up_axis``: 'y' or 'z'; None = the
    format's (glTF is Y-up by its specification, turned into our Z-up frame; others Z-up)."""
    written = str(path)
    return Mesh(path=Path(written), path_as_written=written,
                up_axis=mesh_up_axis(Path(written).suffix) if up_axis is None else up_axis)


def library_mesh(library: str, root, id: str, *, up_axis: str | None = None, scale: float = 1.0) -> Mesh:
    """Model ``id`` of an asset library folder ``root`` in layout ``library`` ('shapenet',
    'shapenet_v1', 'gso', 'objaverse'; docs/scene_spec.md "Asset libraries"), as the YAML's
    ``mesh: {library:, root:, id:}``: a relative root resolves against ``Scene(base_dir=...)``;
    ``up_axis`` defaults to the layout's, ``scale`` (metres per file unit) to 1."""
    if library not in LAYOUTS:
        raise SpecError(f"unknown library layout {library!r}; expected one of {', '.join(LAYOUTS)}",
                        file=PYTHON_FILE, field="library_mesh.library")
    try:
        check_id(LAYOUTS[library], id)
    except LibraryError as e:
        raise SpecError(str(e), file=PYTHON_FILE, field="library_mesh.id") from None
    written = f"{str(root).rstrip('/')}/{LAYOUTS[library].pattern.format(id=id)}"
    return Mesh(path=Path(written), path_as_written=written, scale=float(scale),
                up_axis=LAYOUTS[library].up_axis if up_axis is None else up_axis,
                library=LibraryRef(layout=library, root=str(root), id=id))


def library_picks(library: str, root, category: str, count: int, seed: int = 0) -> tuple[str, ...]:
    """``count`` distinct model ids of ``category`` (a ShapeNet synset) picked by ``seed``: picks
    0 .. count-1 of the YAML's ``{category:, pick:, seed:}`` (``root`` as a path from here)."""
    try:
        return tuple(pick_id(library, Path(root), category, k, seed) for k in range(int(count)))
    except LibraryError as e:
        raise SpecError(str(e), file=PYTHON_FILE, field=f"library_picks.{e.key}") from None


def pbr_set_material(folder, *, name: str | None = None, resolution: str | None = None,
                     disp_scale_m: float | None = None, **principled) -> PrincipledMaterial:
    """A principled material whose texture and roughness, metallic and normal maps come from a
    PBR texture set folder in Poly Haven's naming, as the YAML's ``pbr_set:`` (docs/scene_spec.md
    "PBR texture sets"); a relative ``folder`` resolves against ``Scene(base_dir=...)``;
    ``principled``: the other PrincipledMaterial fields (specular, ...)."""
    return PrincipledMaterial(color=None, pbr_set=PbrSet(folder=str(folder), name=name, resolution=resolution,
                                                         disp_scale_m=disp_scale_m), **principled)


def _resolved_pbr_set(mat: PrincipledMaterial, base: Path, field: str) -> PrincipledMaterial:
    """A pbr_set_material with its set found in its folder (as the parser finds it)."""
    p = mat.pbr_set
    try:
        found = find_set((base / Path(p.folder).expanduser()).resolve(), p.name, p.resolution)
        pbr, texture = pbr_records(found, p.folder, p.disp_scale_m)
    except PbrSetError as e:
        raise SpecError(str(e), file=PYTHON_FILE, field=f"{field}.pbr_set.{e.key}") from None
    return dataclasses.replace(mat, pbr_set=pbr, texture=texture, color=None)


def image_texture(path) -> Texture:
    """An image file as a material's texture (``DiffuseMaterial(texture=...)``); a relative path
    resolves against ``Scene(base_dir=...)``."""
    return Texture(kind="image", path=Path(str(path)), path_as_written=str(path))


def keyframe(time_s: float, *, translation=(0.0, 0.0, 0.0), rotation_deg=(0.0, 0.0, 0.0), order: str = "xyz",
             eye=None, target=None, up=(0.0, 0.0, 1.0)) -> Keyframe:
    """A pose at ``time_s`` on the sequence clock: translation + Euler rotation (an object's
    world_from_object, or a camera's / rig's world_from_cam), or a camera looking from ``eye`` at
    ``target`` (OpenCV axes, ``up`` the world direction up the image)."""
    if eye is not None:
        if target is None:
            raise SpecError("a look-at keyframe needs both eye and target", file=PYTHON_FILE, field="keyframe")
        return Keyframe(time_s=float(time_s), pose=look_at(eye, target, up))
    return Keyframe(time_s=float(time_s), pose=Rigid3(rotation_from_euler_deg(rotation_deg, order), translation))


def trajectory(keyframes: Iterable[Keyframe], interpolation: str = "spline") -> TrajectorySpec:
    """Keyframes (strictly increasing times) interpolated 'linear' or 'spline' (C2)."""
    return TrajectorySpec(interpolation=interpolation, keyframes=tuple(keyframes))


def sequence(*, fps: float | None = None, frames: int | None = None, start_s: float = 0.0, timestamps_s=None,
             flow_steps=(1,), tracks: TrackSpec | None = None) -> SequenceSpec:
    """The clock of a sequence (``Scene(sequence=...)``): ``fps`` and ``frames`` (frame k at
    start_s + k / fps), or explicit ``timestamps_s``; flow truth for frame steps ``flow_steps``."""
    if timestamps_s is None:
        if fps is None or frames is None:
            raise SpecError("give fps and frames, or timestamps_s", file=PYTHON_FILE, field="sequence")
        times = tuple(start_s + k / fps for k in range(int(frames)))  # the parser's formula
    else:
        fps = frames = None
        times = tuple(float(t) for t in timestamps_s)
    return SequenceSpec(fps=fps, frames=frames, start_s=start_s, timestamps_s=times,
                        flow_steps=tuple(flow_steps), tracks=tracks)


def obj(name: str, geometry, *, material=None, translation=(0.0, 0.0, 0.0), rotation_deg=(0.0, 0.0, 0.0),
        order: str = "xyz", scale=1.0, instance_id: int | None = None, motion=None, trajectory=None,
        parent: str | None = None, joint: JointSpec | None = None, visible_s=None) -> SceneObject:
    """A :class:`SceneObject` placed as a YAML ``transform`` (translation, rotation_deg with its
    Euler ``order``, scale: one number or three). ``geometry``: a shape, a target, :func:`mesh`
    or a mesh file's path. ``material``: a material or the name of one in
    ``Scene(materials=...)``; None = a mesh file's own materials, else grey diffuse. In a
    sequence: ``trajectory`` (keyframes of world_from_object, or parent_from_object with a
    ``parent``), ``joint``, ``visible_s``; with a joint or a parent and no trajectory the
    translation/rotation is the rest pose in the parent frame. Its object_id is set by
    :func:`Scene` (its position in ``objects``); ``instance_id`` defaults to it."""
    if isinstance(geometry, (str, PathLike)):
        geometry = mesh(geometry)
    scale3 = tuple(float(s) for s in (scale if isinstance(scale, (tuple, list)) else (scale,) * 3))
    pose = Rigid3(rotation_from_euler_deg(rotation_deg, order), translation)
    if isinstance(geometry, Mesh):  # the file's own materials unless one is given (Scene checks it has any)
        geometry = dataclasses.replace(geometry, own_materials=material is None)
    animation = None
    if trajectory is not None or parent is not None or joint is not None or visible_s is not None:
        animation = Animation(parent=parent, trajectory=trajectory, joint=joint, rest=pose,
                              visible_s=None if visible_s is None else tuple(float(t) for t in visible_s))
    return SceneObject(name=name, geometry=geometry, transform=Transform(world_from_object=pose, scale=scale3),
                       material=material if material is not None else DiffuseMaterial(), object_id=0,
                       instance_id=0 if instance_id is None else instance_id, motion=motion,
                       animation=animation)


def camera(name: str, *, size, fx: float | None = None, fy: float | None = None, cx: float | None = None,
           cy: float | None = None, fov_deg: float | None = None, model: str = "pinhole", dist=(),
           skew: float = 0.0, optics=None, imaging=None) -> CameraSpec:
    """A :class:`CameraSpec` with the YAML's defaults: ``fov_deg`` or ``fx`` (``fy`` = fx),
    principal point at the image centre ((W - 1) / 2, (H - 1) / 2)."""
    W, H = size
    if fov_deg is not None:
        fx = fy = (W / 2) / math.tan(math.radians(fov_deg) / 2)
    if fx is None:
        raise SpecError("give fx or fov_deg", file=PYTHON_FILE, field=f"cameras.{name}")
    return CameraSpec(name=name, model=model, width=W, height=H, fx=fx, fy=fx if fy is None else fy,
                      cx=(W - 1) / 2 if cx is None else cx, cy=(H - 1) / 2 if cy is None else cy,
                      skew=skew, dist=tuple(dist), fov_deg=fov_deg, optics=optics, imaging=imaging)


def _checked(value, arg: str, kinds: tuple, *, mapping: bool = False):
    """``value`` of argument ``arg`` when it is a list or tuple (or, where ``mapping``, a mapping
    name -> item) of ``kinds``; a SpecError naming the argument (and the item) otherwise, never
    the AttributeError of a later ``.name``."""
    names = " | ".join(k.__name__ for k in kinds)

    def check(item, field):
        if not isinstance(item, kinds):
            raise SpecError(f"expected a {names}, got {type(item).__name__} {item!r:.60}", file=PYTHON_FILE,
                            field=field)
    if mapping and isinstance(value, Mapping):
        for k, v in value.items():
            check(v, f"{arg}.{k}")
        return value
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Iterable):
        form = "a list (or a mapping name -> item)" if mapping else "a list"
        raise SpecError(f"expected {form} of {names}, got {type(value).__name__} {value!r:.60}",
                        file=PYTHON_FILE, field=arg)
    value = list(value)
    for i, item in enumerate(value):
        check(item, f"{arg}[{i}]")
    return value


def _one(value, arg: str, kind: type, what: str):
    """``value`` when it is None or a ``kind``; SpecError naming the argument otherwise."""
    if value is not None and not isinstance(value, kind):
        raise SpecError(f"expected {what} or None, got {type(value).__name__} {value!r:.60}", file=PYTHON_FILE,
                        field=arg)
    return value


def _named(things, what: str) -> dict:
    """A mapping name -> thing (a mapping, or things with a ``name``), names filled in."""
    if isinstance(things, Mapping):
        return {k: dataclasses.replace(v, name=k) for k, v in things.items()}
    out = {}
    for t in things:
        if t.name in out:
            raise SpecError(f"duplicate {what} name {t.name!r}", file=PYTHON_FILE, field=f"{what}s.{t.name}")
        out[t.name] = t
    return out


def _resolved_paths(x, base: Path, field: str):
    """``x`` with every file it names (a mesh, a texture, an environment map) resolved against
    ``base`` as the parser resolves a spec's paths; a mesh also gets the files it names and
    whether its own materials are rendered (``own_materials`` asked for and the file has some)."""
    if isinstance(x, (tuple, list)):
        return type(x)(_resolved_paths(v, base, f"{field}[{i}]") for i, v in enumerate(x))
    if not dataclasses.is_dataclass(x) or isinstance(x, type):
        return x
    if isinstance(x, PrincipledMaterial) and x.pbr_set is not None and x.texture is None:
        x = _resolved_pbr_set(x, base, field)
    changes = {}
    for f in dataclasses.fields(x):
        if not f.init or f.name in ("where", "pbr_set"):  # a set is found by _resolved_pbr_set
            continue
        v = getattr(x, f.name)
        if f.name == "path" and v is not None and hasattr(x, "path_as_written"):
            written = x.path_as_written or str(v)  # a dataclass given only its path
            v = (base / Path(written).expanduser()).resolve()
            if not v.is_file():
                raise SpecError(f"file not found: {written!r} (looked for {v})", file=PYTHON_FILE, field=field)
            if not x.path_as_written:
                changes["path_as_written"] = written
        elif dataclasses.is_dataclass(v) or isinstance(v, (tuple, list)):
            v = _resolved_paths(v, base, f"{field}.{f.name}")
        if v is not getattr(x, f.name):
            changes[f.name] = v
    if getattr(x, "texture", None) is not None and getattr(x, "color", None) is not None:
        changes["color"] = None  # a texture replaces the colour (the YAML gives one of the two)
    out = dataclasses.replace(x, **changes) if changes else x
    if isinstance(out, Mesh):
        try:
            if out.library is not None:  # every path built from the id checked inside the root
                library_file(out.library.layout, (base / Path(out.library.root).expanduser()).resolve(), out.library.id)
            scan = scan_mesh_file(out.path, mesh_within(out))
        except LibraryError as e:
            raise SpecError(str(e), file=PYTHON_FILE, field=f"{field}.{e.key}") from None
        except AssetFileError as e:
            raise SpecError(f"{e.message} (the mesh of {PYTHON_FILE}: {field})", file=str(e.file), line=e.line) \
                from None
        out = dataclasses.replace(out, own_materials=out.own_materials and scan.has_materials,
                                  files=tuple(AssetFile(path=r.path, path_as_written=r.written) for r in scan.refs))
    return out


def _views_on_clock(views, seq: SequenceSpec | None) -> tuple:
    """View sets whose trajectory placement has no times yet get the sequence's timestamps."""
    out = []
    for vs in views:
        p = vs.placement
        if isinstance(p, TrajectorySpec):
            p = TrajectoryPath(trajectory=p, times_s=())
        if isinstance(p, TrajectoryPath) and not p.times_s and seq is not None:
            p = TrajectoryPath(trajectory=p.trajectory, times_s=seq.timestamps_s)
        out.append(vs if p is vs.placement else dataclasses.replace(vs, placement=p))
    return tuple(out)


def Scene(name: str = "scene", *, objects: Iterable[SceneObject] = (), lights: Iterable = (),
          cameras: Iterable[CameraSpec] | Mapping[str, CameraSpec] = (), rigs: Iterable[Rig] | Mapping = (),
          views: Iterable[ViewSet] = (), materials: Mapping = frozen_mapping(), render: RenderSettings | None = None,
          crossview: CrossviewSpec | None = None, variation=None, seed: int = 0, description: str = "",
          base_dir=None, sequence: SequenceSpec | None = None, truth=None) -> SceneSpec:
    """A validated :class:`SceneSpec` (what ``load_spec`` gives for the same YAML, warnings
    included). Object ids are the objects' positions (1-based); a material given by name is
    looked up in ``materials``; ``base_dir`` is where relative mesh and image paths resolve
    (default: the current directory); ``sequence`` (:func:`sequence`) makes it a sequence: an
    animated object's pose at frame 0 and a trajectory placement's times come from it;
    ``truth``: a :class:`scenegen.spec.model.TruthSpec` (albedo and light truth on request).
    SpecError naming the field on a bad value."""
    objects = _checked(objects, "objects", (SceneObject,))  # the arguments' types first: errors name them
    lights = _checked(lights, "lights", get_args(Light))
    cameras = _checked(cameras, "cameras", (CameraSpec,), mapping=True)
    rigs = _checked(rigs, "rigs", (Rig,), mapping=True)
    views = _checked(views, "views", (ViewSet,))
    materials = _checked(materials, "materials", get_args(Material), mapping=True)
    render = _one(render, "render", RenderSettings, "RenderSettings")
    crossview = _one(crossview, "crossview", CrossviewSpec, "a CrossviewSpec")
    sequence = _one(sequence, "sequence", SequenceSpec, "a SequenceSpec (scenegen.api.sequence)")
    base = Path(base_dir).resolve() if base_dir is not None else Path.cwd()
    mats = {k: _resolved_paths(v, base, f"materials.{k}") for k, v in _named(materials, "material").items()}
    objs = []
    for i, o in enumerate(objects):
        mat = o.material
        if isinstance(mat, str):
            if mat not in mats:
                raise SpecError(f"undefined material {mat!r}; defined: {', '.join(mats) or 'none'}",
                                file=PYTHON_FILE, field=f"objects[{i}].material")
            mat = mats[mat]
        else:
            mat = _resolved_paths(mat, base, f"objects[{i}].material")
        o = dataclasses.replace(o, object_id=i + 1, instance_id=o.instance_id or i + 1, material=mat,
                                geometry=_resolved_paths(o.geometry, base, f"objects[{i}].mesh"))
        if o.animation is not None and sequence is not None:
            o = dataclasses.replace(o, transform=start_transform(o.animation, o.transform.scale, objs, sequence))
        objs.append(o)
    spec = SceneSpec(name=name, description=description, seed=seed, render=render or RenderSettings(),
                     materials=frozen_mapping(mats), objects=tuple(objs),
                     lights=tuple(_resolved_paths(li if li.name is not None else dataclasses.replace(
                         li, name=default_light_name(i)), base, f"lights[{i}]") for i, li in enumerate(lights)),
                     cameras=frozen_mapping(_named(cameras, "camera")), rigs=frozen_mapping(_named(rigs, "rig")),
                     view_sets=_views_on_clock(views, sequence), file=PYTHON_FILE, base_dir=base,
                     crossview=crossview, variation=variation, sequence=sequence,
                     truth=truth)
    return check_spec(spec)


def render(spec: SceneSpec, out_dir, **options) -> RenderSummary:
    """Render a spec built in code into ``out_dir``, as ``scenegen render`` renders its
    :func:`to_yaml` text (``options``: frames, spp, seed, variant, resume, progress; see
    :func:`scenegen.pipeline.run.render_spec`)."""
    source = SpecSource(to_yaml(check_spec(spec)), PYTHON_FILE, str(spec.base_dir))
    return render_spec(source, out_dir, **options)
