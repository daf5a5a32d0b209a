"""A spec loaded into Mitsuba: :class:`LoadedScene`, the face through which the pipeline renders,
casts truth and casts visibility rays (Mitsuba behind one door).

It is the three parts of the render package together: the :class:`~scenegen.render.description.SceneDescription`
(what the scene is: picklable, hashed, no Mitsuba), the :class:`~scenegen.render.device.DeviceScene`
built from it (the only holder of Mitsuba handles) and the explicit renders and casts of a
:class:`~scenegen.render.caster.Caster` (camera, pose, time and lighting stated in each call).
Built by :func:`build_scene` (called by :func:`scenegen.render.load_scene` once the backend has
set the variant).
"""
from __future__ import annotations

from dataclasses import dataclass

from scenegen.render.caster import Caster
from scenegen.render.description import SceneDescription, describe, object_key
from scenegen.render.device import build_device
from scenegen.spec import model as m

__all__ = ["LoadedScene", "build_scene", "object_key"]


@dataclass(frozen=True)
class LoadedScene(Caster):
    """A description on its device, with the caster's methods; read-only views of both."""

    @property
    def description(self) -> SceneDescription:
        return self.device.description

    # what the pipeline reads of the description (cameras.json, exports, truth across time)
    @property
    def cameras(self) -> dict:
        """Camera name -> scenegen.geometry.camera.Camera."""
        return self.description.cameras

    @property
    def optics(self) -> dict:
        """Camera name -> scenegen.geometry.optics.Optics (or None)."""
        return self.description.optics

    @property
    def meshes_world(self) -> dict:
        return self.description.meshes_world

    @property
    def part_meshes(self) -> dict:
        return self.description.part_meshes

    @property
    def boards(self) -> dict:
        return self.description.boards

    @property
    def objects(self) -> list:
        return self.description.object_records

    @property
    def movers(self) -> dict:
        return self.description.movers

    @property
    def timeline(self):
        return self.description.timeline

    @property
    def motion_subframes(self) -> int:
        return self.description.motion_subframes

    @property
    def sampler(self) -> str:
        return self.description.sampler

    # Mitsuba's side, for tests and benchmarks that call the render modules directly
    @property
    def scene(self):
        return self.device.scene

    @property
    def id_tables(self) -> tuple:
        return self.device.id_tables

    @property
    def sensors(self) -> dict:
        return self.device.sensors

    @property
    def alpha_masked(self) -> bool:
        return self.device.alpha_masked

    @property
    def light_scales(self) -> tuple:
        """The lighting the device was last rendered with (state of Mitsuba's copy, not an input)."""
        return self.device.light_scales

    def timed(self):
        """The device's still world and one scene per moving object (:meth:`scenegen.render.device.DeviceScene.timed`)."""
        return self.device.timed()

    @property
    def moving(self) -> list:
        return self.device.moving

    @property
    def animated(self) -> list:
        return self.device.animated


def build_scene(spec: m.SceneSpec, *, spp: int, sampler: str, max_depth: int) -> LoadedScene:
    """Describe ``spec`` and load it into Mitsuba (current variant) with one of our sensors per
    spec camera."""
    return LoadedScene(build_device(describe(spec, spp=spp, sampler=sampler, max_depth=max_depth)))
