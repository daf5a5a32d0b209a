"""The Mitsuba adapter, and the only package that imports Mitsuba or Dr.Jit.

The one way in is :func:`load_scene`: it picks a working libLLVM and the variant
(:mod:`.backend`), imports Mitsuba, and loads a spec into a
:class:`~scenegen.render.scene.LoadedScene`, a scene in three parts: its
:class:`~scenegen.render.description.SceneDescription` (no Mitsuba; frozen, picklable, hashed),
the :class:`~scenegen.render.device.DeviceScene` built from it (the only holder of Mitsuba
handles) and the :class:`~scenegen.render.caster.Caster`'s renders, per-pixel truth and
visibility casts, each with its camera, pose, time and lighting stated. Modules: :mod:`.backend`
(variant and libLLVM), :mod:`.sensor` (our camera model as a Mitsuba sensor, with
:mod:`.drjit_ops`), :mod:`.materials`, :mod:`.objects`, :mod:`.lights` (one translation function
per spec kind), :mod:`.description`, :mod:`.device`, :mod:`.caster`, :mod:`.scene` (loading),
:mod:`.frames` (renders), :mod:`.truth` (the truth pass), :mod:`.raycast` (visibility).

Importing this package points Dr.Jit at a libLLVM >= 16 before anything imports it (Debian's
libLLVM 15 aborts the process on the first min/max kernel; docs/conventions.md).
"""
from scenegen.render.backend import BackendError, configure_llvm, load_mitsuba

configure_llvm()


def load_scene(spec, *, variant: str = "auto", spp: int | None = None):
    """Load a spec (:class:`scenegen.spec.model.SceneSpec`) into Mitsuba in ``variant`` ('auto'
    picks cuda, then llvm, then scalar) with ``spp`` samples per pixel (default: the spec's).
    Raises :class:`BackendError` when the variant cannot run here."""
    load_mitsuba(variant)
    # imported once a variant is set: the sensor subclasses a variant's mi.Sensor at import
    from scenegen.render.scene import build_scene

    rs = spec.render
    return build_scene(spec, spp=rs.spp if spp is None else int(spp), sampler=rs.sampler, max_depth=rs.max_depth)


__all__ = ["BackendError", "configure_llvm", "load_mitsuba", "load_scene"]
