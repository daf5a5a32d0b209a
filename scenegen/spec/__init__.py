"""The YAML scene spec: parsing into frozen dataclasses, validation, view resolution.

Layers, each importing only those before it: :mod:`.model` (dataclasses holding every default,
unit and range) <- :mod:`.views` (view sets -> poses) <- :mod:`.parse` (one module per YAML
section) <- :mod:`.load` (file / text entry points) <- :mod:`.serialize` (JSON-able form, hash),
:mod:`.variants` (``--variants``), :mod:`.source` (what a worker needs to rebuild a spec).
:mod:`.reference` renders the defaults table of ``docs/scene_spec.md``. Nothing here imports
Mitsuba. The format is documented in ``docs/scene_spec.md``.

    >>> spec = load_spec("scenes/examples/orbit_objects.yaml")   # doctest: +SKIP
    >>> views = resolve_views(spec)                               # doctest: +SKIP
"""
from scenegen.errors import SpecError, Where
from scenegen.spec.load import TOP_LEVEL_KEYS, derive_seed, load_spec, parse_spec
from scenegen.spec.model import (
    AreaLight, ArucoGridTarget, Blob, Box, CameraSpec, CharucoTarget, CheckerboardTarget,
    CirclePath, ConductorMaterial, ConstantLight, Cylinder, DiffuseMaterial, EnvmapLight, Light,
    LinePath, LookAt, LookAtList, Material, Mesh, Orbit, Placement, Plane, PlasticMaterial,
    PointLight, PoseList, RandomPoses, RenderSettings, Rig, RigMember, SceneObject, SceneSpec,
    Shape, Sphere, SpotLight, Target, Texture, Torus, Transform, View, ViewSet,
)
from scenegen.spec.serialize import canonical_json, spec_sha256, spec_to_dict
from scenegen.spec.to_yaml import check_spec, same_spec, to_yaml
from scenegen.spec.views import resolve_views

__all__ = [
    "SpecError", "Where", "load_spec", "parse_spec", "resolve_views", "spec_to_dict",
    "spec_sha256", "canonical_json", "derive_seed", "TOP_LEVEL_KEYS", "to_yaml", "same_spec",
    "check_spec",
    "AreaLight", "ArucoGridTarget", "Blob", "Box", "CameraSpec", "CharucoTarget",
    "CheckerboardTarget", "CirclePath", "ConductorMaterial", "ConstantLight", "Cylinder",
    "DiffuseMaterial", "EnvmapLight", "Light", "LinePath", "LookAt", "LookAtList", "Material",
    "Mesh", "Orbit", "Placement", "Plane", "PlasticMaterial", "PointLight", "PoseList",
    "RandomPoses", "RenderSettings", "Rig", "RigMember", "SceneObject", "SceneSpec", "Shape",
    "Sphere", "SpotLight", "Target", "Texture", "Torus", "Transform", "View", "ViewSet",
]
