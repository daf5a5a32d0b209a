"""Lens and time effects of a camera (``lens``, ``shutter``, ``chromatic_aberration``) and the
``motion`` of a view set or object, as :mod:`scenegen.geometry.optics` records (their defaults
are that module's; units and ranges: :mod:`scenegen.spec.model.cameras`)."""
from __future__ import annotations

from scenegen.geometry import optics as o
from scenegen.geometry.camera import MODELS
from scenegen.located_yaml import Fields, Node
from scenegen.spec.parse.fields import parse_record

OPTICS_KEYS = ("lens", "shutter", "chromatic_aberration")


def parse_optics(f: Fields, model: str) -> o.Optics | None:
    """``lens``, ``shutter`` and ``chromatic_aberration`` of a camera (its fields ``f``), or None."""
    if not any(k in f for k in OPTICS_KEYS):
        return None
    lens = shutter = ca = None
    if "lens" in f:
        if MODELS[model].wide_angle:
            perspective = ", ".join(n for n, cm in MODELS.items() if not cm.wide_angle)
            raise f.get("lens").error(f"the thin lens is for perspective models ({perspective}); "
                                      f"a {model} has no single focus plane")
        lens = parse_record(f.get("lens"), o.ThinLens, "a thin lens")
    if "shutter" in f:
        shutter = parse_record(f.get("shutter"), o.Shutter, "a shutter")
    if "chromatic_aberration" in f:
        ca = parse_record(f.get("chromatic_aberration"), o.ChromaticAberration,
                          "per-channel focal scales")
    return o.Optics(lens=lens, shutter=shutter, chromatic_aberration=ca)


def parse_motion(node: Node) -> o.Motion:
    """Constant linear (m/s) and angular (deg/s, rotation vector) velocities."""
    return parse_record(node, o.Motion, "a motion")
