"""The projector as a sensor kind: the ``projectors:`` section, a rig member that lights the views
of its rig's cameras with a sequence of patterns (docs/scene_spec.md, "Projectors";
docs/dataset_format.md, "Structured light").

A projector is an inverse camera: its ``intrinsics`` are a camera of the ``cameras:`` section's
models (pinhole, OpenCV distortion, skew, principal point anywhere, its own resolution), read by
the same parser; the renderer's emitter projects each lit point through that model
(:mod:`scenegen.render.projector`), so distortion is exact without an inverse.

Radiometry, stated once: a projector pixel showing pattern value ``p`` in [0, 1] emits the radiant
intensity (W/sr, per colour channel) ::

    I = intensity_w_sr * (black_level + (1 - black_level) * p ** gamma) * cos(alpha) ** k

toward the points it lights, ``alpha`` the angle between the ray and the projector's optical axis
and ``k`` the fall-off law's exponent (``falloff: none`` k = 0, ``cos4`` k = 4: a lens's natural
fall-off). A surface point at distance ``d`` whose normal makes the angle ``theta`` with the
direction to the projector centre receives the irradiance ``E = I cos(theta) / d^2`` (W/m^2)
where nothing lies between them; a point outside the projector's image gets nothing.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from scenegen.errors import Where
from scenegen.imaging.patterns import PatternSequence
from scenegen.imaging.projector_sequences import AXES, SEQUENCES, SequenceOptions
from scenegen.spec.model.meta import SEED_MAX, field_info, param, part, where_field
from scenegen.spec.parse.cameras import parse_camera
from scenegen.spec.parse.fields import check_keys, read_fields, read_value, write_fields
from scenegen.spec.sensors.kind import LIGHT, SensorKind

FALLOFF_EXPONENTS = {"none": 0, "cos4": 4}
_INTRINSICS = "intrinsics"


@dataclass(frozen=True, kw_only=True)
class ProjectorSpec:
    """A projector under ``projectors:``: its camera model, radiometry and pattern sequence."""

    name: str
    intrinsics: Any = part(unit="scenegen.spec.model.cameras.CameraSpec: the projector's model, "
                                "resolution and intrinsics, written as a camera of `cameras:`")
    intensity_w_sr: tuple[float, float, float] = param((1.0, 1.0, 1.0), unit="W/sr", lo=0.0,
                                                       kind="color")  # radiant intensity of a white pixel on axis
    gamma: float = param(1.0, unit="unitless", lo=0.0, lo_open=True, hi=10.0)  # pattern value -> output exponent
    black_level: float = param(0.0, unit="fraction of white", lo=0.0, hi=1.0, hi_open=True)  # a black pixel's light
    falloff: str = param("none", unit="fall-off law", choices=tuple(FALLOFF_EXPONENTS))
    patterns: str = param("gray", unit="pattern sequence", choices=tuple(SEQUENCES))
    pattern_axes: str = param("both", unit="coded axes", choices=tuple(AXES))  # De Bruijn: the first
    pattern_inverse: bool = param(True, unit="flag")  # gray/binary: each bit pattern followed by its inverse
    pattern_white_black: bool = param(True, unit="flag")  # gray/binary: an all-white and an all-black pattern first
    phase_steps: int = param(4, unit="steps per period", lo=3, hi=64)  # phase_shift
    phase_periods_px: tuple[float, ...] | None = param(
        None, unit="projector pixels, coarsest first", lo=0.0, lo_open=True,
        doc_default="the axis length, then 8 times finer while >= 8 px")  # phase_shift
    stripe_px: int = param(4, unit="projector pixels", lo=1, hi=4096)  # debruijn: stripe width
    dots_density: float = param(0.1, unit="fraction of lit dots", lo=0.0, lo_open=True, hi=1.0)  # dots
    dot_px: int = param(1, unit="projector pixels", lo=1, hi=4096)  # dots: dot size
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX, derived="seed32(scene seed, field path)")  # dots
    linear_patterns: bool = param(False, unit="flag")  # also write each pattern's clean linear EXR
    where: Where | None = where_field()

    @property
    def falloff_exponent(self) -> int:
        return FALLOFF_EXPONENTS[self.falloff]

    def to_camera(self):
        """The projector's :class:`scenegen.geometry.camera.Camera`."""
        return self.intrinsics.to_camera()

    def pattern_sequence(self) -> PatternSequence:
        """The sequence it shows, in order, at its resolution."""
        c = self.intrinsics
        return SEQUENCES[self.patterns](c.width, c.height, SequenceOptions(
            axes=self.pattern_axes, inverses=self.pattern_inverse, references=self.pattern_white_black,
            phase_steps=self.phase_steps, phase_periods_px=self.phase_periods_px, stripe_px=self.stripe_px,
            dots_seed=self.seed, dots_density=self.dots_density, dot_px=self.dot_px))

    def relative_output(self, values) -> np.ndarray:
        """(…) float64 emitted fraction of ``intensity_w_sr`` for pattern values in [0, 1] (clipped)."""
        p = np.clip(np.asarray(values, np.float64), 0.0, 1.0)
        return self.black_level + (1.0 - self.black_level) * p ** self.gamma


def parse_projector(node, name, ctx) -> ProjectorSpec:
    """One entry of ``projectors:``: ``intrinsics`` as a camera (no optics or imaging chain: a
    projector's image is its pattern), then the radiometry and the sequence."""
    f = check_keys(node.as_mapping("a projector (intrinsics, intensity_w_sr, gamma, ..., patterns)"), ProjectorSpec,
                   required=(_INTRINSICS,))
    inode = f.get(_INTRINSICS)
    cam = parse_camera(inode, name, ctx)
    if cam.optics is not None or cam.imaging is not None:
        bad = next(k for k in inode.as_mapping().keys() if k not in _CAMERA_KEYS)
        raise inode.as_mapping().get(bad).error("a projector's intrinsics take the camera model keys only "
                                                f"({', '.join(_CAMERA_KEYS)}); got {bad!r}")
    values = read_fields(f, ProjectorSpec)
    values["seed"] = (read_value(f.get("seed"), field_info(ProjectorSpec, "seed")) if "seed" in f
                      else ctx.seed_for(node.path))
    p = ProjectorSpec(name=name, intrinsics=cam, where=node.where, **values)
    try:
        p.pattern_sequence()  # e.g. phase periods shorter than the projector's axis
    except ValueError as e:
        raise (f.get("phase_periods_px") or node).error(f"pattern sequence {p.patterns!r}: {e}") from None
    return p


_CAMERA_KEYS = ("model", "size", "fx", "fy", "cx", "cy", "skew", "dist", "fov_deg", "mask_beyond_fold")


def projector_to_yaml(p: ProjectorSpec) -> dict:
    c = p.intrinsics
    intr = {"model": c.model, "size": [c.width, c.height],
            **write_fields(c, ("fx", "fy") if c.fov_deg is not None else ())}
    return {_INTRINSICS: intr, **write_fields(p)}


PROJECTOR = SensorKind(name="projector", section="projectors", model=ProjectorSpec, parse=parse_projector,
                       produces=LIGHT, truth=("projector_uv", "projector_lit", "projector_code"),
                       to_yaml=projector_to_yaml)
