"""The scene spec as frozen dataclasses: what :func:`scenegen.spec.load_spec` returns.

Conventions (see :mod:`scenegen.geometry.conventions`): the world is right-handed and Z-up, in
metres; camera axes are OpenCV's (+x right, +y down, +z forward); pixel (0, 0) is the CENTRE of
the top-left pixel. Angles are degrees only in fields named ``*_deg`` (as written by the user);
resolved rotations are matrices inside :class:`~scenegen.geometry.pose.Rigid3`. Quaternions are
(w, x, y, z).

Every record that came from the YAML keeps ``where`` (file, line, field path) so that later
stages can report a problem at its source with :meth:`scenegen.errors.SpecError.at`.
``where`` takes no part in equality.

Paths to files (meshes, images) are absolute, resolved relative to the spec file's directory;
``*_as_written`` keeps the user's spelling for provenance and hashing.

Each value a user writes is declared with :func:`~scenegen.spec.model.meta.param`: its default,
unit and range live on the field (:func:`~scenegen.spec.model.meta.field_info`), nowhere else.
Camera models are the registry's (:data:`scenegen.geometry.camera.MODELS`), bit depths
:data:`scenegen.geometry.color.BIT_DEPTHS`.

Modules, by idea: :mod:`.meta` (field metadata), :mod:`.render`, :mod:`.materials`,
:mod:`.geometry` (shapes, meshes, targets, transforms, objects), :mod:`.lights`, :mod:`.cameras`
(cameras, rigs), :mod:`.views` (view sets, views), :mod:`.crossview`, :mod:`.variation`,
:mod:`.timeline` (sequence clock, trajectories, joints, tracks), :mod:`.placement` (objects
dropped by a rigid-body simulation), :mod:`.scene` (SceneSpec). This package re-exports them all.
"""
from scenegen.spec.model import imaging as _imaging  # noqa: F401 (describes the imaging records)
from scenegen.spec.model.cameras import RIG_TYPES, CameraSpec, Rig, RigMember
from scenegen.spec.model.crossview import CROSSVIEW_PAIR_MODES, CrossviewSpec, MatchSetSpec
from scenegen.spec.model.geometry import (
    ARUCO_DICTIONARIES, MESH_SUFFIXES, AssetFile, SHAPE_KINDS, TARGET_KINDS, ArucoGridTarget, Blob, Box,
    CharucoTarget, CheckerboardTarget, Cylinder, LibraryRef, Mesh, Plane, SceneObject, Shape, Sphere, Target,
    Torus, Transform,
)
from scenegen.spec.model.lights import (
    BEAM_WIDTH_FRACTION, LIGHT_TYPES, AreaLight, ConstantLight, DirectionalLight, EnvmapLight, Light,
    PointLight, SpotLight,
)
from scenegen.spec.model.materials import (
    CONDUCTOR_NAMES, IMAGE_SUFFIXES, MATERIAL_TYPES, PROCEDURAL_TEXTURE_KINDS, TEXTURE_KINDS,
    ConductorMaterial, DielectricMaterial, DiffuseMaterial, Material, PlasticMaterial,
    PbrMap, PbrSet, PrincipledMaterial, SurfaceMaps, Texture, ThinDielectricMaterial,
)
from scenegen.spec.model.meta import (
    ID_MAX, SEED_MAX, WORLD_UP, FieldInfo, Meta, field_info, frozen_mapping, spec_fields,
)
from scenegen.spec.model.placement import DROP_ORIENTATIONS, PLACEMENT_TYPES, DropPlacement
from scenegen.spec.model.render import RENDER_VARIANTS, SAMPLERS, RenderSettings, effective_spp
from scenegen.spec.model.scene import SceneSpec
from scenegen.spec.model.timeline import (
    Animation, JointKeyframe, JointSpec, Keyframe, SequenceSpec, TrackSpec, TrajectorySpec,
)
from scenegen.spec.model.truth import TruthSpec
from scenegen.spec.model.variation import (
    CameraVariation, LightVariation, ObjectVariation, PoseJitter, VariationSpec,
)
from scenegen.spec.model.views import (
    CirclePath, LinePath, LookAt, LookAtList, Orbit, Placement, PoseList, RandomPoses,
    TrajectoryPath, View, ViewSet,
)

__all__ = [
    "RIG_TYPES", "CameraSpec", "Rig", "RigMember",
    "CROSSVIEW_PAIR_MODES", "CrossviewSpec", "MatchSetSpec",
    "ARUCO_DICTIONARIES", "MESH_SUFFIXES", "SHAPE_KINDS", "TARGET_KINDS", "ArucoGridTarget", "Blob",
    "Box", "CharucoTarget", "CheckerboardTarget", "Cylinder", "LibraryRef", "Mesh", "Plane", "SceneObject",
    "Shape", "Sphere", "Target", "Torus", "Transform",
    "BEAM_WIDTH_FRACTION", "LIGHT_TYPES", "AreaLight", "ConstantLight", "EnvmapLight", "Light",
    "PointLight", "SpotLight", "DirectionalLight",
    "CONDUCTOR_NAMES", "IMAGE_SUFFIXES", "MATERIAL_TYPES", "PROCEDURAL_TEXTURE_KINDS",
    "TEXTURE_KINDS", "ConductorMaterial", "DielectricMaterial", "DiffuseMaterial", "Material",
    "PbrMap", "PbrSet", "PlasticMaterial", "PrincipledMaterial", "SurfaceMaps", "Texture", "ThinDielectricMaterial",
    "AssetFile",
    "ID_MAX", "SEED_MAX", "WORLD_UP", "FieldInfo", "Meta", "field_info", "frozen_mapping",
    "spec_fields",
    "DROP_ORIENTATIONS", "PLACEMENT_TYPES", "DropPlacement",
    "RENDER_VARIANTS", "SAMPLERS", "RenderSettings", "effective_spp",
    "SceneSpec",
    "Animation", "JointKeyframe", "JointSpec", "Keyframe", "SequenceSpec", "TrackSpec",
    "TrajectorySpec",
    "TruthSpec",
    "CameraVariation", "LightVariation", "ObjectVariation", "PoseJitter", "VariationSpec",
    "CirclePath", "LinePath", "LookAt", "LookAtList", "Orbit", "Placement", "PoseList",
    "RandomPoses", "TrajectoryPath", "View", "ViewSet",
]
