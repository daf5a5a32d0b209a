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
from pathlib import Path
from typing import Iterable, Mapping

from scenegen.errors import SpecError
from scenegen.geometry.pose import Rigid3
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
from scenegen.spec.model.meta import frozen_mapping
from scenegen.spec.source import SpecSource
from scenegen.spec.to_yaml import PYTHON_FILE

__all__ = [
    "Scene", "camera", "obj", "render", "to_yaml", "check_spec", "same_spec", "SpecError",
    "AreaLight", "ArucoGridTarget", "Blob", "Box", "CameraSpec", "CharucoTarget", "CheckerboardTarget",
    "CirclePath", "ConductorMaterial", "ConstantLight", "CrossviewSpec", "Cylinder", "DiffuseMaterial",
    "EnvmapLight", "LinePath", "LookAt", "LookAtList", "MatchSetSpec", "Orbit", "Plane", "PlasticMaterial",
    "PointLight", "PoseList", "RandomPoses", "RenderSettings", "Rig", "RigMember", "SceneObject", "SceneSpec",
    "Sphere", "SpotLight", "Texture", "Torus", "Transform", "ViewSet",
]


def obj(name: str, geometry, *, material=None, translation=(0.0, 0.0, 0.0), rotation_deg=(0.0, 0.0, 0.0),
        order: str = "xyz", scale=1.0, instance_id: int | None = None, motion=None) -> SceneObject:
    """A :class:`SceneObject` placed as a YAML ``transform`` (translation, rotation_deg with its
    Euler ``order``, scale: one number or three); ``material`` a material or the name of one in
    ``Scene(materials=...)``; None = the default grey diffuse. Its object_id is set by
    :func:`Scene` (its position in ``objects``); ``instance_id`` defaults to it."""
    scale3 = tuple(float(s) for s in (scale if isinstance(scale, (tuple, list)) else (scale,) * 3))
    pose = Rigid3(rotation_from_euler_deg(rotation_deg, order), translation)
    return SceneObject(name=name, geometry=geometry, transform=Transform(world_from_object=pose, scale=scale3),
                       material=material if material is not None else DiffuseMaterial(), object_id=0,
                       instance_id=0 if instance_id is None else instance_id, motion=motion)


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


def Scene(name: str = "scene", *, objects: Iterable[SceneObject] = (), lights: Iterable = (),
          cameras: Iterable[CameraSpec] | Mapping[str, CameraSpec] = (), rigs: Iterable[Rig] | Mapping = (),
          views: Iterable[ViewSet] = (), materials: Mapping = frozen_mapping(), render: RenderSettings | None = None,
          crossview: CrossviewSpec | None = None, variation=None, seed: int = 0, description: str = "",
          base_dir=None, truth=None) -> SceneSpec:
    """A validated :class:`SceneSpec` (what ``load_spec`` gives for the same YAML, warnings
    included). Object ids are the objects' positions (1-based); a material given by name is
    looked up in ``materials``; ``base_dir`` is where relative mesh and image paths resolve
    (default: the current directory); ``truth``: a :class:`scenegen.spec.model.TruthSpec` (albedo and
    light truth on request). SpecError naming the field on a bad value."""
    mats = _named(materials, "material")
    objs = []
    for i, o in enumerate(objects):
        mat = o.material
        if isinstance(mat, str):
            if mat not in mats:
                raise SpecError(f"undefined material {mat!r}; defined: {', '.join(mats) or 'none'}",
                                file=PYTHON_FILE, field=f"objects[{i}].material")
            mat = mats[mat]
        objs.append(dataclasses.replace(o, object_id=i + 1, instance_id=o.instance_id or i + 1, material=mat))
    spec = SceneSpec(name=name, description=description, seed=seed, render=render or RenderSettings(),
                     materials=frozen_mapping(mats), objects=tuple(objs), lights=tuple(lights),
                     cameras=frozen_mapping(_named(cameras, "camera")), rigs=frozen_mapping(_named(rigs, "rig")),
                     view_sets=tuple(views), file=PYTHON_FILE,
                     base_dir=Path(base_dir).resolve() if base_dir is not None else Path.cwd(),
                     crossview=crossview, variation=variation, truth=truth)
    return check_spec(spec)


def render(spec: SceneSpec, out_dir, **options) -> RenderSummary:
    """Render a spec built in code into ``out_dir``, as ``scenegen render`` renders its
    :func:`to_yaml` text (``options``: frames, spp, seed, variant, resume, progress; see
    :func:`scenegen.pipeline.run.render_spec`)."""
    source = SpecSource(to_yaml(check_spec(spec)), PYTHON_FILE, str(spec.base_dir))
    return render_spec(source, out_dir, **options)
