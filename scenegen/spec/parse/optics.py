"""Lens and time effects of a camera (``lens``, ``shutter``, ``chromatic_aberration``) and the
``motion`` of a view set or object, as :mod:`scenegen.geometry.optics` records (their defaults
are that module's; units and ranges: :mod:`scenegen.spec.model.cameras`)."""
from __future__ import annotations

from scenegen.geometry import optics as o
from scenegen.geometry.camera import MODELS
from scenegen.located_yaml import Fields, Node
from scenegen.spec.parse.read import read_float, read_vec3

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
        lf = f.get("lens").as_mapping("a thin lens (f_number, focus_distance_m, pixel_pitch_um)")
        lf.check(required=("f_number", "focus_distance_m", "pixel_pitch_um"))
        L = o.ThinLens
        lens = L(f_number=read_float(lf, L, "f_number"),
                 focus_distance_m=read_float(lf, L, "focus_distance_m"),
                 pixel_pitch_um=read_float(lf, L, "pixel_pitch_um"))
    if "shutter" in f:
        sf = f.get("shutter").as_mapping("a shutter (exposure_s, rolling_readout_s)").check(
            optional=("exposure_s", "rolling_readout_s"))
        S = o.Shutter
        shutter = S(exposure_s=read_float(sf, S, "exposure_s"),
                    rolling_readout_s=read_float(sf, S, "rolling_readout_s"))
    if "chromatic_aberration" in f:
        cf = f.get("chromatic_aberration").as_mapping(
            "per-channel focal scales (red_focal_scale, blue_focal_scale)").check(
            optional=("red_focal_scale", "blue_focal_scale"))
        C = o.ChromaticAberration
        ca = C(red_focal_scale=read_float(cf, C, "red_focal_scale"),
               blue_focal_scale=read_float(cf, C, "blue_focal_scale"))
    return o.Optics(lens=lens, shutter=shutter, chromatic_aberration=ca)


def parse_motion(node: Node) -> o.Motion:
    """Constant linear (m/s) and angular (deg/s, rotation vector) velocities."""
    f = node.as_mapping("a motion (linear_velocity_mps, angular_velocity_deg_s)").check(
        optional=("linear_velocity_mps", "angular_velocity_deg_s"))
    M = o.Motion
    return M(linear_velocity_mps=read_vec3(f, M, "linear_velocity_mps"),
             angular_velocity_deg_s=read_vec3(f, M, "angular_velocity_deg_s"))
