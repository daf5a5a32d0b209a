"""A spec loaded into Mitsuba: :class:`LoadedScene`, the one object through which the pipeline
renders, casts truth and casts visibility rays (Mitsuba behind one door).

Built by :func:`build_scene` (called by :func:`scenegen.render.load_scene` once the backend has
set the variant): objects (:mod:`.objects`), lights (:mod:`.lights`), one of our sensors per spec
camera (:mod:`.sensor`).
"""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field

import mitsuba as mi
import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.render import raycast, sensor as sensor_mod
from scenegen.render.albedo import albedo_pass
from scenegen.render.correspond import correspond_in_kernel
from scenegen.render.animate import animated_entry, place_animated
from scenegen.render.frames import render_ideal, render_view
from scenegen.render.lights import light_entry, light_key, loaded_emitters
from scenegen.render.objects import moving_entry, object_entries
from scenegen.render.timed import build_timed
from scenegen.render.truth import camera_rays, prepare_camera, shape_id_table, truth_pass
from scenegen.spec import model as m
from scenegen.spec.assets_check import located
from scenegen.spec.timeline import Timeline, is_animated, moves_within_frame


@dataclass
class LoadedScene:
    """A loaded Mitsuba scene plus what the pipeline needs to render views of it."""

    scene: object  # mi.Scene
    sensors: dict  # camera name -> ScenegenSensor
    cameras: dict  # camera name -> scenegen.geometry.camera.Camera
    meshes_world: dict  # object name -> trimesh.Trimesh in the world frame (for export)
    id_tables: tuple  # (object id table, instance id table) for the truth pass
    boards: dict = field(default_factory=dict)  # object name -> (assets.targets.Board, world_from_board)
    optics: dict = field(default_factory=dict)  # camera name -> scenegen.geometry.optics.Optics (or None)
    moving: list = field(default_factory=list)  # objects that move during the exposure (objects.Moving)
    motion_subframes: int = 1
    objects: list = field(default_factory=list)  # [{name, object_id, instance_id, kind}] for cameras.json
    emitters: list = field(default_factory=list)  # per spec light, spec order: (Mitsuba key of
    # its power, loaded value = spec power, key of its sampling weight, loaded weight)
    light_scales: tuple = ()  # factor on each spec light's power now in the loaded scene
    part_meshes: dict = field(default_factory=dict)  # scene-dict key -> world trimesh of one part
    # of a mesh rendered with its own materials
    alpha_masked: bool = False  # some surface has an alpha mask: truth rays test its opacity
    sampler: str = "ldsampler"  # the sensors' Mitsuba sampler plugin (it rounds spp up: effective_spp)
    timeline: object = None  # scenegen.spec.timeline.Timeline of a sequence, else None
    animated: list = field(default_factory=list)  # objects placed per time (animate.Animated)
    time_s: float | None = None  # the clock time the animated objects are at (None: frame 0)
    animated_params: object = None  # mi.traverse of the scene, made on the first placement
    scene_entries: dict = field(default_factory=dict)  # the scene dict's shapes and emitters (no sensors)
    entry_ids: tuple = ({}, {})  # (dict key -> object id, dict key -> instance id)
    movers: dict = field(default_factory=dict)  # object id -> spec object that moves within a frame
    timed_scenes: object = None  # render.timed.TimedScenes, made on first use (:meth:`timed`)
    view_rows: OrderedDict = field(default_factory=OrderedDict)  # view -> what the pipeline derived of its
    # rows (rolling-shutter poses, scenegen.pipeline.view): made once per view, not per truth call

    @property
    def variant(self) -> str:
        """The Mitsuba variant the scene was loaded in."""
        return mi.variant()

    # --- the door: everything the pipeline asks of Mitsuba
    def set_time(self, t_s: float | None) -> None:
        """Move the sequence's objects to time ``t_s`` of the clock (renders, truth and
        visibility casts then see them there); None or a static scene: nothing to do."""
        if t_s is None or not self.animated or self.time_s == float(t_s):
            return
        place_animated(self, float(t_s))
        self.time_s = float(t_s)

    def render(self, camera_name: str, cam_from_world: Rigid3, *, spp: int, seed: int, motion=None,
               light_scales=None) -> np.ndarray:
        """Linear float32 (H, W, 3) of a view (:func:`scenegen.render.frames.render_view`)."""
        return render_view(self, camera_name, cam_from_world, spp=spp, seed=seed, motion=motion,
                           light_scales=light_scales)

    def render_ideal(self, sensor_camera_name: str, camera, cam_from_world: Rigid3, *, spp: int, seed: int,
                     light_scales=None) -> np.ndarray:
        """Linear float32 (H, W, 3) of an ideal pinhole (:func:`scenegen.render.frames.render_ideal`)."""
        return render_ideal(self, sensor_camera_name, camera, cam_from_world, spp=spp, seed=seed,
                            light_scales=light_scales)

    def truth(self, camera, cam_from_world: Rigid3, row_poses=None, as_stored: bool = False,
              row_moves=None) -> dict[str, np.ndarray]:
        """Per-pixel truth of a camera at a pose (:func:`scenegen.render.truth.truth_pass`);
        ``row_moves`` {object id: ((H, 3, 3) R, (H, 3) t world_from_object, (H,) present)}: the
        moving objects where they are at each row's time (rolling shutter)."""
        timed = None if row_moves is None else (self.timed(), row_moves)
        return truth_pass(self.scene, camera, cam_from_world, self.id_tables, row_poses=row_poses, as_stored=as_stored,
                          alpha_masked=self.alpha_masked, timed=timed)

    def albedo(self, camera, cam_from_world: Rigid3) -> np.ndarray:
        """(H, W, 3) float32 diffuse albedo per pixel centre (:func:`scenegen.render.albedo.albedo_pass`)."""
        return albedo_pass(self.scene, camera, cam_from_world, self.alpha_masked)

    def timed(self):
        """The still world and one scene per moving object (:mod:`scenegen.render.timed`),
        built on the first call."""
        if self.timed_scenes is None:
            movers = {oid: object_entries(obj, object_key(obj), _scratch()) for oid, obj in self.movers.items()}
            keys = {k for entries in movers.values() for k in entries}
            refs = {oid: obj.transform.world_from_object for oid, obj in self.movers.items()}
            self.timed_scenes = build_timed({k: v for k, v in self.scene_entries.items() if k not in keys},
                                            movers, refs, *self.entry_ids)
        return self.timed_scenes

    def camera_rays(self, camera) -> np.ndarray:
        """(H*W, 3) float64 unit rays of the camera's pixel centres, row-major, as the truth pass
        casts them (:func:`scenegen.render.truth.camera_rays`, read-only)."""
        return camera_rays(camera)

    def visible_from(self, center_world, points_world, moves=None) -> np.ndarray:
        """(N,) bool visibility of world points from a centre (3,), or each from its own centre
        (N, 3) (:func:`scenegen.render.raycast.visible_from`); ``moves`` {object id: ((N, 3, 3)
        R, (N, 3) t world_from_object, (N,) present)}: the moving objects where they are when each
        point is seen (rolling shutter)."""
        timed = None if moves is None else (self.timed(), moves)
        return raycast.visible_from(self.scene, center_world, points_world, alpha_masked=self.alpha_masked,
                                    timed=timed)

    @property
    def kernel_correspondences(self) -> bool:
        """:meth:`correspond` applies: a vectorised variant and no alpha masks (their holes need
        the visibility cast of :meth:`visible_from`)."""
        return not self.alpha_masked and not mi.variant().startswith("scalar")

    def correspond(self, points_world, camera, cam_from_world: Rigid3):
        """Correspondences of truth points (H, W, 3) (float64, NaN = no surface) in a view, in
        one kernel (:mod:`scenegen.render.correspond`: the definition of
        :func:`scenegen.crossview.correspondence.correspond`); needs :attr:`kernel_correspondences`."""
        return correspond_in_kernel(self.scene, points_world, camera, cam_from_world)

    def surface_points(self, camera, cam_from_world: Rigid3, uv) -> np.ndarray:
        """(N, 3) world points seen through sub-pixel positions (:func:`scenegen.render.raycast.surface_points`)."""
        return raycast.surface_points(self.scene, camera, cam_from_world, uv, self.alpha_masked)[0]

    def surface_hits(self, camera, cam_from_world: Rigid3, uv, rows=None, moves=None):
        """((N, 3) world points seen through sub-pixel positions, (N,) their object ids or None):
        :meth:`surface_points` through a rolling shutter (``rows``: the camera's world_from_cam
        per row; ``moves``: the moving objects at the positions' rows, then the ids come back)."""
        timed = None if moves is None else (self.timed(), moves)
        return raycast.surface_points(self.scene, camera, cam_from_world, uv, self.alpha_masked, rows, timed)


def _scratch() -> LoadedScene:
    """A throwaway record for building a second copy of an object's shapes."""
    return LoadedScene(scene=None, sensors={}, cameras={}, meshes_world={}, id_tables=())


def object_key(obj) -> str:
    """The key of a spec object in the scene dict."""
    return f"obj_{obj.object_id:04d}"


def build_scene(spec: m.SceneSpec, *, spp: int, sampler: str, max_depth: int) -> LoadedScene:
    """Load ``spec`` into Mitsuba (current variant) with one of our sensors per spec camera."""
    sensor_mod.register()
    built = LoadedScene(scene=None, sensors={}, cameras={}, meshes_world={}, id_tables=(), sampler=sampler)
    d: dict = {"type": "scene", "integrator": {"type": "path", "max_depth": int(max_depth)}}
    object_ids, instance_ids = {}, {}
    for obj in spec.objects:
        with located(obj, f"object {obj.name!r}"):  # asset errors name the spec's file:line
            entries = object_entries(obj, object_key(obj), built)
        d.update(entries)
        for key, entry in entries.items():
            mesh = built.part_meshes.get(key, built.meshes_world[obj.name])
            if obj.motion is not None and not obj.motion.is_static:
                built.moving.append(moving_entry(key, obj, entry, mesh))
            if is_animated(obj):
                built.animated.append(animated_entry(key, obj, entry, mesh))
            object_ids[key] = obj.object_id
            instance_ids[key] = obj.instance_id
        if moves_within_frame(obj):
            built.movers[obj.object_id] = obj
        built.objects.append({"name": obj.name, "object_id": obj.object_id, "instance_id": obj.instance_id,
                              "kind": type(obj.geometry).__name__.lower()})
    for i, light in enumerate(spec.lights):
        d[light_key(i)] = light_entry(light)
    if built.movers:
        built.timeline = Timeline(spec)
    built.motion_subframes = spec.render.motion_subframes if built.moving or built.animated else 1
    for name, cam_spec in spec.cameras.items():
        cam = cam_spec.to_camera()
        built.cameras[name] = cam
        built.optics[name] = cam_spec.optics
        shutter = getattr(cam_spec.optics, "shutter", None)
        timed = shutter is not None and (shutter.exposure_s > 0 or shutter.rolling_readout_s > 0)
        d[f"sensor_{name}"] = sensor_mod.sensor_dict(cam, spp=spp, sampler=sampler, name=name, timed=timed)
    # what the timed casts' still scene shares (the Mitsuba shapes themselves), no sensors
    built.scene_entries = {k: v for k, v in d.items() if k not in ("type", "integrator") and not k.startswith("sensor_")}
    built.entry_ids = (object_ids, instance_ids)
    built.scene = mi.load_dict(d)
    built.emitters = loaded_emitters(built.scene, spec.lights)
    built.light_scales = (1.0,) * len(spec.lights)
    built.sensors = {s.camera_name: s for s in built.scene.sensors()}
    built.id_tables = shape_id_table(built.scene, object_ids, instance_ids)
    if built.animated:  # at frame 0, where the geometry was placed, hiding what is absent then
        built.time_s = float(spec.sequence.timestamps_s[0])
        place_animated(built, built.time_s)
    for cam in built.cameras.values():
        prepare_camera(cam)  # the truth pass's ray table, made here rather than in frame 0
    return built
