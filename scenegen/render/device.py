"""A scene description on a device: :class:`DeviceScene`, the second of the render package's
three parts and the only holder of Mitsuba handles (the loaded scene, its sensors, the shape id
tables, the emitters' loaded powers, the scenes of the timed casts).

What it holds besides is the state of those handles, never an input of a result: where the
moving objects are (:meth:`DeviceScene.place_at`) and at what power the lights are
(:func:`scenegen.render.lights.set_lighting`). Every cast and render states its time and
lighting (:class:`scenegen.render.caster.Caster`) and the device is moved there first; both
placements are computed from the loaded geometry, not from the previous state, so a result does
not depend on what was cast before it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import mitsuba as mi

from scenegen.render import projector as projector_mod
from scenegen.render import sensor as sensor_mod
from scenegen.render.animate import Animated, animated_entry, place_animated
from scenegen.render.description import SceneDescription
from scenegen.render.lights import light_entry, light_key, loaded_emitters
from scenegen.render.objects import Moving, moving_entry, object_entries
from scenegen.render.timed import TimedScenes, build_timed
from scenegen.render.truth import prepare_camera, shape_id_table
from scenegen.spec.assets_check import located
from scenegen.spec.timeline import is_animated


@dataclass(eq=False)
class DeviceScene:
    """Mitsuba's copy of a :class:`SceneDescription` (built by :func:`build_device`)."""

    description: SceneDescription
    scene: object  # mi.Scene
    sensors: dict  # camera name -> ScenegenSensor
    id_tables: tuple  # (object id table, instance id table) for the truth pass
    alpha_masked: bool  # some surface has an alpha mask: truth rays test its opacity
    emitters: list  # per spec light, spec order: (Mitsuba key of its power, loaded value = spec
    # power, key of its sampling weight, loaded weight)
    moving: list[Moving]  # objects that move during the exposure
    animated: list[Animated]  # a sequence's objects, placed per time
    scene_entries: dict  # the scene dict's shapes and emitters (no sensors): the timed casts' still scene
    entry_ids: tuple  # (dict key -> object id, dict key -> instance id)
    light_scales: tuple = ()  # device state: the factor on each spec light's power now loaded
    time_s: float | None = None  # device state: the clock time the animated objects are at
    animated_params: object = None  # mi.traverse of the scene, made on the first placement
    timed_scenes: TimedScenes | None = field(default=None, repr=False)  # made on first use (:meth:`timed`)
    alone_scenes: dict = field(default_factory=dict, repr=False)  # object id -> (its scene alone,
    # world_from_ref), made on first use (:mod:`scenegen.render.alone`)
    projectors: dict = field(default_factory=dict)  # projector name -> ProjectorEmitter (off until shown)

    # read-only views of the description, for the modules that render (frames, lights, animate)
    @property
    def cameras(self) -> dict:
        return self.description.cameras

    @property
    def optics(self) -> dict:
        return self.description.optics

    @property
    def sampler(self) -> str:
        return self.description.sampler

    @property
    def motion_subframes(self) -> int:
        return self.description.motion_subframes

    @property
    def timeline(self):
        return self.description.timeline

    def time_or_rest(self, time_s: float | None) -> float | None:
        """``time_s``, or for None the time the description's geometry rests at."""
        return self.description.rest_time_s if time_s is None else float(time_s)

    def place_at(self, time_s: float | None) -> None:
        """Put a sequence's objects where the timeline has them at ``time_s`` (None: at rest,
        frame 0); a static scene: nothing to do. Skipped when they are there already."""
        t = self.time_or_rest(time_s)
        if t is None or not self.animated or self.time_s == t:
            return
        place_animated(self, t)
        self.time_s = t

    def timed(self) -> TimedScenes:
        """The still world and one scene per moving object (:mod:`scenegen.render.timed`),
        built on the first call."""
        if self.timed_scenes is None:
            movers = {oid: object_entries(d)[0] for oid, d in self.description.movers.items()}
            keys = {k for entries in movers.values() for k in entries}
            refs = {oid: d.spec.transform.world_from_object for oid, d in self.description.movers.items()}
            self.timed_scenes = build_timed({k: v for k, v in self.scene_entries.items() if k not in keys},
                                            movers, refs, *self.entry_ids)
        return self.timed_scenes


def build_device(desc: SceneDescription) -> DeviceScene:
    """Load ``desc`` into Mitsuba (current variant) with one of our sensors per camera."""
    sensor_mod.register()
    d: dict = {"type": "scene", "integrator": {"type": "path", "max_depth": desc.max_depth}}
    object_ids, instance_ids = {}, {}
    moving, animated, alpha_masked = [], [], False
    for o in desc.objects:
        obj = o.spec
        with located(obj, f"object {obj.name!r}"):  # asset errors name the spec's file:line
            entries, alpha = object_entries(o)
        alpha_masked |= alpha
        d.update(entries)
        part_meshes = {p.key: p.mesh_world for p in o.parts}
        for key, entry in entries.items():
            mesh = part_meshes.get(key, o.mesh_world)
            if o.moves_in_exposure:
                moving.append(moving_entry(key, obj, entry, mesh))
            if is_animated(obj):
                animated.append(animated_entry(key, obj, entry, mesh))
            object_ids[key] = obj.object_id
            instance_ids[key] = obj.instance_id
    for i, light in enumerate(desc.lights):
        d[light_key(i)] = light_entry(light)
    if desc.projectors:
        projector_mod.register()
    for name in desc.projectors:
        d[projector_mod.projector_key(name)] = projector_mod.projector_entry(name)
    for name, cam in desc.cameras.items():
        shutter = getattr(desc.optics[name], "shutter", None)
        timed = shutter is not None and (shutter.exposure_s > 0 or shutter.rolling_readout_s > 0)
        d[f"sensor_{name}"] = sensor_mod.sensor_dict(cam, spp=desc.spp, sampler=desc.sampler, name=name, timed=timed)
    # what the timed casts' still scene shares (the Mitsuba shapes themselves), no sensors
    entries = {k: v for k, v in d.items() if k not in ("type", "integrator") and not k.startswith("sensor_")
               and k not in {projector_mod.projector_key(n) for n in desc.projectors}}
    scene = mi.load_dict(d)
    device = DeviceScene(desc, scene, {s.camera_name: s for s in scene.sensors()},
                         shape_id_table(scene, object_ids, instance_ids), alpha_masked,
                         loaded_emitters(scene, desc.lights), moving, animated, entries, (object_ids, instance_ids),
                         light_scales=(1.0,) * len(desc.lights),
                         projectors={e.projector_name: e for e in scene.emitters()
                                     if isinstance(e, projector_mod.ProjectorEmitter)})
    device.place_at(None)  # at frame 0, where the geometry was placed, hiding what is absent then
    for cam in desc.cameras.values():
        prepare_camera(cam)  # the truth pass's ray table, made here rather than in frame 0
    return device
