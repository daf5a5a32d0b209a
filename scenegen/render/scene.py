"""Adapter from the spec's frozen dataclasses to a loaded Mitsuba scene, one function per kind.

Geometry is placed in the world in float64 numpy (object transforms applied to the vertices),
so the dataset's world meshes and the rendered ones are the same triangles. Spheres are Mitsuba's
analytic sphere (exact depth); every other shape is a triangle mesh from :mod:`scenegen.shapes`.
Texture UVs: Mitsuba's bitmap puts v = 0 at the image's top row, the project's convention, so
UVs pass through unchanged (checked in tests/test_render.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import mitsuba as mi
import numpy as np
import trimesh

from scenegen import shapes, textures
from scenegen.pose import Rigid3
from scenegen.render import sensor as sensor_mod
from scenegen.render.truth import shape_id_table
from scenegen.spec import model as m

#: Board pictures are black/white; printed paper is neither 0 nor 1 in reflectance.
BOARD_BLACK, BOARD_WHITE = 0.03, 0.85


@dataclass
class BuiltScene:
    """A loaded Mitsuba scene plus what the pipeline needs to render views of it."""

    scene: object  # mi.Scene
    sensors: dict  # camera name -> ScenegenSensor
    cameras: dict  # camera name -> scenegen.camera.Camera
    meshes_world: dict  # object name -> trimesh.Trimesh in the world frame (for export)
    id_tables: tuple  # (object id table, instance id table) for the truth pass
    boards: dict = field(default_factory=dict)  # object name -> (targets.Board, world_from_board)
    optics: dict = field(default_factory=dict)  # camera name -> scenegen.optics.Optics (or None)
    moving: list = field(default_factory=list)  # objects that move during the exposure (_Moving)
    motion_subframes: int = 1
    objects: list = field(default_factory=list)  # [{name, object_id, instance_id, kind}] for cameras.json
    emitters: list = field(default_factory=list)  # per spec light, spec order: (Mitsuba key of
    # its power, loaded value = spec power, key of its sampling weight, loaded weight)
    light_scales: tuple = ()  # factor on each spec light's power now in the loaded scene


@dataclass
class _Moving:
    """An object that moves over the exposure: its Mitsuba parameter keys and mid-exposure state."""

    key: str  # the object's key in the scene dict
    motion: object  # scenegen.optics.Motion (world frame, about the object origin)
    world_from_object: Rigid3  # mid-exposure placement
    sphere_to_world: np.ndarray | None = None  # (4, 4) for an analytic sphere
    vertices: np.ndarray | None = None  # (V, 3) float64 world vertices at mid-exposure
    normals: np.ndarray | None = None  # (V, 3) vertex normals, or None (flat shading)


def _rgb(c) -> dict:
    return {"type": "rgb", "value": [float(x) for x in c]}


def _bitmap(img: np.ndarray, wrap_mode: str = "repeat") -> dict:
    """Linear float32 (H, W, 3) reflectance as a raw (non-sRGB) Mitsuba bitmap texture.

    Procedural textures tile seamlessly, so they repeat (no visible UV seam on spheres and tori);
    board pictures clamp, so no opposite edge bleeds into the board's border."""
    return {"type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(img, dtype=np.float32)),
            "raw": True, "filter_type": "bilinear", "wrap_mode": wrap_mode}


def texture_image(tex: m.Texture) -> np.ndarray:
    if tex.kind == "image":
        return textures.load_image(tex.path)
    return textures.make_texture(tex.kind, dict(tex.params), tex.seed)


def _reflectance(color, texture: m.Texture | None) -> dict:
    return _bitmap(texture_image(texture)) if texture is not None else _rgb(color)


def material_dict(mat) -> dict:
    """Mitsuba BSDF for a spec material."""
    if isinstance(mat, m.DiffuseMaterial):
        return {"type": "diffuse", "reflectance": _reflectance(mat.color, mat.texture)}
    if isinstance(mat, m.PlasticMaterial):
        refl = _reflectance(mat.color, mat.texture)
        if mat.roughness > 0:
            return {"type": "roughplastic", "diffuse_reflectance": refl, "alpha": float(mat.roughness),
                    "int_ior": float(mat.ior), "distribution": "ggx"}
        return {"type": "plastic", "diffuse_reflectance": refl, "int_ior": float(mat.ior)}
    if isinstance(mat, m.ConductorMaterial):
        if mat.roughness > 0:
            return {"type": "roughconductor", "material": mat.material, "alpha": float(mat.roughness),
                    "distribution": "ggx"}
        return {"type": "conductor", "material": mat.material}
    raise TypeError(f"unknown material {type(mat).__name__}")


def board_material(board) -> dict:
    img = board.image.astype(np.float32) / 255.0
    refl = BOARD_BLACK + (BOARD_WHITE - BOARD_BLACK) * img
    return {"type": "diffuse", "reflectance": _bitmap(np.repeat(refl[..., None], 3, axis=2), "clamp")}


def geometry_mesh(geom, spec_seed: int = 0):
    """(trimesh in the object frame, board or None) for a spec geometry (not spheres)."""
    if isinstance(geom, m.Plane):
        return shapes.plane(geom.size), None
    if isinstance(geom, m.Box):
        return shapes.box(geom.size), None
    if isinstance(geom, m.Sphere):
        return shapes.sphere(geom.radius), None
    if isinstance(geom, m.Cylinder):
        return shapes.cylinder(geom.radius, geom.height), None
    if isinstance(geom, m.Torus):
        return shapes.torus(geom.major_radius, geom.minor_radius), None
    if isinstance(geom, m.Blob):
        return shapes.blob(geom.radius, geom.amplitude, geom.frequency, geom.seed, geom.subdivisions), None
    if isinstance(geom, m.Mesh):
        return shapes.load_mesh(geom.path), None
    from scenegen import targets

    board = targets.board_from_spec(geom)
    # the spec's target object is the board centred on its origin, print facing +z
    mesh = board.mesh()
    mesh.vertices = board.object_from_board().apply(mesh.vertices)
    return mesh, board


def _place(mesh: trimesh.Trimesh, tf: m.Transform) -> trimesh.Trimesh:
    """Object -> world in float64: scale, then rotate and translate (normals follow)."""
    v = np.asarray(mesh.vertices, dtype=np.float64) * np.asarray(tf.scale, dtype=np.float64)
    v = tf.world_from_object.apply(v)
    faces = np.asarray(mesh.faces)
    if np.prod(tf.scale) < 0:  # a mirroring scale flips the winding
        faces = faces[:, ::-1]
    out = trimesh.Trimesh(vertices=v, faces=faces, process=False)
    uv = getattr(mesh.visual, "uv", None)
    if uv is not None:
        out.visual = trimesh.visual.TextureVisuals(uv=np.asarray(uv, dtype=np.float64))
    return out


def mitsuba_mesh(name: str, mesh: trimesh.Trimesh, bsdf: dict, smooth: bool):
    """A Mitsuba mesh from world-frame triangles (float32 on upload), with UVs when present."""
    uv = getattr(mesh.visual, "uv", None)
    props = mi.Properties()
    props["bsdf"] = mi.load_dict(bsdf)
    mm = mi.Mesh(name, len(mesh.vertices), len(mesh.faces), props=props,
                 has_vertex_normals=smooth, has_vertex_texcoords=uv is not None)
    params = mi.traverse(mm)
    # the buffers' own types: Dr.Jit arrays in vectorised variants, dynamic arrays in scalar ones
    put = lambda key, a, dtype: params.__setitem__(key, type(params[key])(np.asarray(a, dtype).ravel()))
    put("vertex_positions", mesh.vertices, np.float32)
    put("faces", mesh.faces, np.uint32)
    if smooth:
        put("vertex_normals", mesh.vertex_normals, np.float32)
    if uv is not None:
        put("vertex_texcoords", uv, np.float32)
    params.update()
    return mm


# shapes whose shading normals are interpolated (curved surfaces approximated by triangles)
_SMOOTH = (m.Cylinder, m.Torus, m.Blob, m.Sphere)


def object_entry(obj: m.SceneObject, built: BuiltScene) -> dict:
    """The Mitsuba dict entry for one object; records its world mesh, board and ids."""
    geom = obj.geometry
    bsdf = material_dict(obj.material)
    if isinstance(geom, m.Sphere):
        s = np.asarray(obj.transform.scale)
        if not np.allclose(s, s[0]):
            raise ValueError(f"object {obj.name!r}: a sphere takes a uniform scale, got {tuple(s)}")
        radius = geom.radius * float(s[0])
        center = obj.transform.world_from_object.t
        # the analytic sphere renders and is intersected exactly; the mesh is only exported
        built.meshes_world[obj.name] = _place(shapes.sphere(geom.radius), obj.transform)
        R = obj.transform.world_from_object.R  # keeps the texture's orientation
        T = np.eye(4)
        T[:3, :3] = R * radius
        T[:3, 3] = center
        return {"type": "sphere", "to_world": mi.ScalarTransform4f(T), "bsdf": bsdf}
    local, board = geometry_mesh(geom)
    world = _place(local, obj.transform)
    built.meshes_world[obj.name] = world
    if board is not None:
        if not np.allclose(obj.transform.scale, 1.0):
            raise ValueError(f"object {obj.name!r}: calibration targets cannot be scaled (their size is exact)")
        built.boards[obj.name] = (board, obj.transform.world_from_object @ board.object_from_board())
        bsdf = board_material(board)
    smooth = isinstance(geom, _SMOOTH) or (isinstance(geom, m.Mesh) and len(world.faces) > 0 and
                                           not _is_faceted(local))
    return mitsuba_mesh(obj.name, world, bsdf, smooth)


def _is_faceted(mesh: trimesh.Trimesh) -> bool:
    """A loaded mesh with per-face vertices (no shared vertices) is flat-shaded."""
    return len(mesh.vertices) >= 3 * len(mesh.faces)


def light_entry(light, world_up=(0.0, 0.0, 1.0)) -> dict:
    if isinstance(light, m.AreaLight):
        T = light.world_from_light.matrix @ np.diag([light.size[0] / 2, light.size[1] / 2, 1.0, 1.0])
        return {"type": "rectangle", "to_world": mi.ScalarTransform4f(T),
                "emitter": {"type": "area", "radiance": _rgb(light.radiance)},
                "bsdf": {"type": "diffuse", "reflectance": _rgb((0.0, 0.0, 0.0))}}
    if isinstance(light, m.PointLight):
        return {"type": "point", "position": [float(x) for x in light.position], "intensity": _rgb(light.intensity)}
    if isinstance(light, m.SpotLight):
        # Mitsuba's spot shines along its local +z: the light frame's +z points at the target
        return {"type": "spot", "to_world": mi.ScalarTransform4f(light.world_from_light.matrix),
                "intensity": _rgb(light.intensity), "cutoff_angle": float(light.cutoff_deg),
                "beam_width": float(light.beam_width_deg)}
    if isinstance(light, m.ConstantLight):
        return {"type": "constant", "radiance": _rgb(light.radiance)}
    if isinstance(light, m.EnvmapLight):
        # Mitsuba's envmap has +y up; ours is +z: rotate +y onto +z, then turn about +z.
        T = mi.ScalarTransform4f().rotate([0, 0, 1], light.rotation_z_deg) @ mi.ScalarTransform4f().rotate([1, 0, 0], 90)
        return {"type": "envmap", "filename": str(light.path), "scale": float(light.scale), "to_world": T}
    raise TypeError(f"unknown light {type(light).__name__}")


#: Mitsuba 3.9 parameters (relative to the light's key in the scene dict) that carry a light's
#: power: scaling one scales the light's contribution linearly (same paths, same samples).
EMITTER_POWER_PARAM = {
    m.AreaLight: "emitter.radiance.value",  # the rectangle's area emitter, W/(m^2 sr)
    m.PointLight: "intensity.value",  # W/sr
    m.SpotLight: "intensity.value",  # on-axis W/sr
    m.ConstantLight: "radiance.value",  # W/(m^2 sr)
    m.EnvmapLight: "scale",  # factor on the image's radiance
}
#: ... and its share of the light samples: Mitsuba picks the emitter of a light sample in
#: proportion to this weight (1 by default), not to power.
EMITTER_WEIGHT_PARAM = {t: ("emitter." if t is m.AreaLight else "") + "sampling_weight"
                        for t in EMITTER_POWER_PARAM}


def _sampling_weights(built: BuiltScene, scales: tuple) -> tuple:
    """Lights that are off get no light samples (as if absent: 6 lights with 5 off would
    otherwise waste 5/6 of them); when every light is off the loaded weights stay."""
    if not any(k > 0 for k in scales):
        return tuple(e[3] for e in built.emitters)
    return tuple(e[3] if k > 0 else 0.0 for e, k in zip(built.emitters, scales))


def set_lighting(built: BuiltScene, light_scales=None) -> None:
    """Put the loaded scene's lights at ``light_scales`` x their spec power (one factor per spec
    light, spec order; None = every light at its spec power).

    Parameters are touched only for lights whose factor differs from the scene's current state,
    so a spec that never changes its lighting renders exactly as loaded; each factor multiplies
    the loaded value, so going back to 1 restores it bit for bit and the result does not depend
    on the order in which views are rendered. A light at 0 stays in the scene as geometry (an
    area light's rectangle is still there, dark) but gets no light samples; lights on keep
    theirs, so scaling lights that stay on changes no sample (a factor of 2 doubles the image
    exactly)."""
    n = len(built.emitters)
    target = (1.0,) * n if light_scales is None else tuple(float(k) for k in light_scales)
    if len(target) != n:
        raise ValueError(f"expected {n} light factors (one per spec light), got {len(target)}")
    if not all(math.isfinite(k) and k >= 0 for k in target):
        raise ValueError(f"light factors must be finite and >= 0, got {target}")
    if target == built.light_scales:
        return
    params = mi.traverse(built.scene)
    weights_now, weights = _sampling_weights(built, built.light_scales), _sampling_weights(built, target)
    for (key, loaded, wkey, _), k, now, w, w_now in zip(built.emitters, target, built.light_scales,
                                                         weights, weights_now):
        if k != now:
            params[key] = loaded * k
        if w != w_now:
            params[wkey] = w
    params.update()
    built.light_scales = target


def build_scene(spec: m.SceneSpec, *, spp: int, sampler: str, max_depth: int) -> BuiltScene:
    """Load ``spec`` into Mitsuba (current variant) with one of our sensors per spec camera."""
    sensor_mod.register()
    built = BuiltScene(scene=None, sensors={}, cameras={}, meshes_world={}, id_tables=())
    d: dict = {"type": "scene", "integrator": {"type": "path", "max_depth": int(max_depth)}}
    object_ids, instance_ids = {}, {}
    for obj in spec.objects:
        key = f"obj_{obj.object_id:04d}"
        d[key] = object_entry(obj, built)
        if obj.motion is not None and not obj.motion.is_static:
            built.moving.append(_moving_entry(key, obj, d[key], built.meshes_world[obj.name]))
        object_ids[key] = obj.object_id
        instance_ids[key] = obj.instance_id
        built.objects.append({"name": obj.name, "object_id": obj.object_id, "instance_id": obj.instance_id,
                              "kind": type(obj.geometry).__name__.lower()})
    for i, light in enumerate(spec.lights):
        d[f"light_{i:04d}"] = light_entry(light)
    built.motion_subframes = spec.render.motion_subframes if built.moving else 1
    for name, cam_spec in spec.cameras.items():
        cam = cam_spec.to_camera()
        built.cameras[name] = cam
        built.optics[name] = cam_spec.optics
        shutter = getattr(cam_spec.optics, "shutter", None)
        timed = shutter is not None and (shutter.exposure_s > 0 or shutter.rolling_readout_s > 0)
        d[f"sensor_{name}"] = sensor_mod.sensor_dict(cam, spp=spp, sampler=sampler, name=name, timed=timed)
    built.scene = mi.load_dict(d)
    if spec.lights:
        params = mi.traverse(built.scene)
        for i, light in enumerate(spec.lights):
            key = f"light_{i:04d}.{EMITTER_POWER_PARAM[type(light)]}"
            wkey = f"light_{i:04d}.{EMITTER_WEIGHT_PARAM[type(light)]}"
            loaded = params[key]
            # copies: the parameter objects are replaced on update
            built.emitters.append((key, type(loaded)(loaded), wkey, float(params[wkey])))
        built.light_scales = (1.0,) * len(spec.lights)
    built.sensors = {s.camera_name: s for s in built.scene.sensors()}
    built.id_tables = shape_id_table(built.scene, object_ids, instance_ids)
    return built


def _moving_entry(key: str, obj: m.SceneObject, entry, mesh_world) -> _Moving:
    if isinstance(entry, dict):  # the analytic sphere
        return _Moving(key, obj.motion, obj.transform.world_from_object,
                       sphere_to_world=np.array(entry["to_world"].matrix, dtype=np.float64))
    normals = None
    if entry.has_vertex_normals():
        normals = np.asarray(mesh_world.vertex_normals, dtype=np.float64)
    return _Moving(key, obj.motion, obj.transform.world_from_object,
                   vertices=np.asarray(mesh_world.vertices, dtype=np.float64), normals=normals)


def place_moving_objects(built: BuiltScene, tau_s: float) -> None:
    """Move every moving object to its pose ``tau_s`` seconds after mid-exposure."""
    if not built.moving:
        return
    from scenegen.optics import world_from_object_at

    params = mi.traverse(built.scene)
    for mv in built.moving:
        # world_from_object(tau) @ object_from_world(mid): maps mid-exposure world points
        move = world_from_object_at(mv.world_from_object, mv.motion, tau_s) @ mv.world_from_object.inverse()
        if mv.sphere_to_world is not None:
            params[f"{mv.key}.to_world"] = mi.ScalarTransform4f(move.matrix @ mv.sphere_to_world)
            continue
        put = lambda k, a: params.__setitem__(k, type(params[k])(np.asarray(a, np.float32).ravel()))
        put(f"{mv.key}.vertex_positions", move.apply(mv.vertices))
        if mv.normals is not None:
            put(f"{mv.key}.vertex_normals", move.rotate(mv.normals))
    params.update()


def render_view(built: BuiltScene, camera_name: str, cam_from_world: Rigid3, *, spp: int, seed: int,
                motion=None, light_scales=None) -> np.ndarray:
    """Linear float32 (H, W, 3) radiance of one view, with the camera's lens and time effects.

    ``cam_from_world`` is the mid-exposure pose; ``motion`` the camera's own velocities;
    ``light_scales`` the factor on each spec light's power (:func:`set_lighting`; None = every
    light at its spec power, whatever an earlier view used). Moving
    objects are rendered in ``built.motion_subframes`` sub-frames (each a slice of the shutter
    interval, with spp / sub-frames samples) and averaged; they are left at mid-exposure, where
    the truth is cast. Chromatic aberration renders each colour channel with its own camera.
    """
    set_lighting(built, light_scales)
    camera = built.cameras[camera_name]
    optics = built.optics.get(camera_name)
    sensor = built.sensors[camera_name]
    ca = getattr(optics, "chromatic_aberration", None)
    channel_cameras = ca.channel_cameras(camera) if ca is not None else (camera,)
    shutter = getattr(optics, "shutter", None)
    exposure = 0.0 if shutter is None else shutter.exposure_s
    n_sub = built.motion_subframes if exposure > 0 else 1
    sub_spp = max(1, int(spp) // n_sub)
    out = np.zeros((camera.height, camera.width, 3), np.float64)
    for k in range(n_sub):
        if n_sub > 1:
            place_moving_objects(built, ((k + 0.5) / n_sub - 0.5) * exposure)
        for c, cam in enumerate(channel_cameras):
            sensor.set_camera(cam, cam_from_world, optics, motion, time_window=(k / n_sub, (k + 1) / n_sub))
            img = np.array(mi.render(built.scene, sensor=sensor, spp=sub_spp, seed=(int(seed) + k) % 2**32),
                           dtype=np.float32)[..., :3]
            if len(channel_cameras) == 3:
                out[..., c] += img[..., c]
            else:
                out += img
    if n_sub > 1:
        place_moving_objects(built, 0.0)
    return (out / n_sub).astype(np.float32)
