"""Cameras (intrinsics, optics, imaging chain) and rigs. Camera models are those of the registry
:data:`scenegen.geometry.camera.MODELS` (names, distortion coefficients, accepted lengths)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from scenegen.errors import Where
from scenegen.geometry import optics
from scenegen.geometry.camera import MODEL_NAMES, Camera
from scenegen.geometry.pose import Rigid3
from scenegen.imaging import ImagingParams, RawOutput, SensorParams
from scenegen.spec.model.meta import describe_foreign, meta, param, part, where_field
from scenegen.spec.model.limits import MAX_IMAGE_SIDE_PX

RIG_TYPES = ("stereo", "multi")
_PX = "pixels"


@dataclass(frozen=True, kw_only=True)
class CameraSpec:
    """Intrinsics (OpenCV pixel convention: pixel (0, 0) is the top-left pixel's centre).

    ``dist`` is in OpenCV's order: opencv k1, k2, p1, p2[, k3[, k4, k5, k6[, s1, s2, s3, s4]]];
    fisheye (Kannala-Brandt, cv2.fisheye) k1, k2, k3, k4; pinhole ().
    """

    name: str  # key under `cameras:`
    model: str = param("pinhole", unit="camera model", choices=MODEL_NAMES)
    width: int = param(unit="pixels", lo=1, hi=MAX_IMAGE_SIDE_PX, key="size[0]")  # whole pixels
    height: int = param(unit="pixels", lo=1, hi=MAX_IMAGE_SIDE_PX, key="size[1]")
    fx: float = param(unit=_PX, lo=0.0, lo_open=True, derived="from fov_deg")  # focal length
    # along u
    fy: float = param(unit=_PX, lo=0.0, lo_open=True, derived="fx")  # focal length along v
    cx: float = param(unit=_PX, derived="(width - 1) / 2")  # principal point u
    cy: float = param(unit=_PX, derived="(height - 1) / 2")  # principal point v
    skew: float = param(0.0, unit=_PX)  # K[0, 1]
    dist: tuple[float, ...] = param((), unit="unitless", derived="zeros, the model's shortest "
                                    "length")  # distortion coefficients, see above
    mask_beyond_fold: bool = param(False, unit="flag", omit_default=True)  # opt-in for a
    # distortion that folds over inside the image: pixels beyond the fold radius get no ray and
    # are invalid in every truth map (otherwise such a camera is refused)
    fov_deg: float | None = param(None, unit="horizontal field of view, degrees", lo=0.0,
                                  lo_open=True, hi=180.0, hi_open=True)  # of the undistorted
    # pinhole as written (fx, fy derived from it: fx = fy = (W/2) / tan(fov/2))
    optics: Any = part(None, unit="scenegen.geometry.optics.Optics: thin lens, shutter (motion "
                                  "blur, rolling shutter), chromatic aberration; None = a pinhole "
                                  "with an instantaneous global shutter")
    imaging: Any = part(None, unit="scenegen.imaging.ImagingParams: the photometric chain "
                                   "(docs/image_formation.md); None = the clean sRGB encoding of "
                                   "the linear render")
    where: Where | None = where_field()

    @property
    def size(self) -> tuple[int, int]:
        """(W, H) in pixels."""
        return (self.width, self.height)

    @property
    def K(self) -> np.ndarray:
        """(3, 3) intrinsic matrix."""
        return np.array([[self.fx, self.skew, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def to_camera(self) -> Camera:
        """The :class:`scenegen.geometry.camera.Camera` for these intrinsics."""
        return Camera(model=self.model, width=self.width, height=self.height, fx=self.fx,
                      fy=self.fy, cx=self.cx, cy=self.cy, skew=self.skew, dist=self.dist,
                      mask_beyond_fold=self.mask_beyond_fold)


@dataclass(frozen=True, kw_only=True, eq=False)
class RigMember:
    """A sensor in a rig: of kind ``kind`` (a key of :data:`scenegen.spec.sensors.SENSOR_KINDS`),
    named ``sensor`` in that kind's section, at ``rig_from_sensor`` in the rig frame, sampling at
    the rig's time plus ``time_offset_s``. ``camera`` and ``rig_from_cam`` read a camera member."""

    name: str = param(unit="member name", derived="'left'/'right' for stereo; for multi the "
                                                  "sensor name")
    sensor: str  # a key of its kind's section (`cameras:` for a camera)
    rig_from_sensor: Rigid3 = part(unit="sensor pose in the rig frame (metres)")
    kind: str = param("camera", unit="sensor kind (scenegen.spec.sensors.SENSOR_KINDS)",
                      omit_default=True)
    time_offset_s: float = param(0.0, unit="seconds, added to the rig's time", omit_default=True)

    @property
    def camera(self) -> str:
        """The camera of a camera member (a key of `cameras:`)."""
        return self._camera_member().sensor

    @property
    def rig_from_cam(self) -> Rigid3:
        """A camera member's pose in the rig frame."""
        return self._camera_member().rig_from_sensor

    def _camera_member(self) -> "RigMember":
        if self.kind != "camera":
            raise AttributeError(f"rig member {self.name!r} is a {self.kind}, not a camera")
        return self


@dataclass(frozen=True, kw_only=True, eq=False)
class Rig:
    """Camera rig. The rig frame has OpenCV camera axes. Stereo: its origin is the left camera
    centre; the right camera centre is at (+baseline_m, 0, 0); with vergence each camera is
    turned by vergence_deg / 2 about its own y axis toward the other (toe-in)."""

    name: str  # key under `rigs:`
    type: str = param(unit="rig type", choices=RIG_TYPES)
    members: tuple[RigMember, ...]  # stereo: (left, right)
    baseline_m: float | None = param(None, unit="metres", lo=0.0, lo_open=True,
                                     doc_default="required (stereo only)")  # distance between
    # the camera centres; None for a multi rig
    vergence_deg: float | None = param(None, unit="degrees", lo=0.0, hi=90.0, hi_open=True,
                                       yaml_default=0.0, doc_default="0 (stereo only)")  # total
    # toe-in angle; None for a multi rig
    where: Where | None = where_field()


# The lens and time effects of a camera are scenegen.geometry.optics' dataclasses (their defaults
# stay there); what the spec needs to read them:
describe_foreign(optics.ThinLens,
                 f_number=meta("unitless", lo=0.0, lo_open=True),
                 focus_distance_m=meta("metres", lo=0.0, lo_open=True),
                 pixel_pitch_um=meta("micrometres", lo=0.0, lo_open=True))
describe_foreign(optics.Shutter,
                 exposure_s=meta("seconds", lo=0.0), rolling_readout_s=meta("seconds", lo=0.0))
describe_foreign(optics.ChromaticAberration,
                 red_focal_scale=meta("unitless", lo=0.5, hi=2.0),
                 blue_focal_scale=meta("unitless", lo=0.5, hi=2.0))
describe_foreign(optics.Motion,
                 linear_velocity_mps=meta("metres / second"),
                 angular_velocity_deg_s=meta("degrees / second"))
# The imaging chain's parameters are scenegen.imaging's (docs/image_formation.md); the fields added
# after datasets existed are left out of the resolved spec at their default (omit_default), so
# that a spec without them keeps its canonical form and hash.
describe_foreign(RawOutput, dng=meta("flag: write raw/<view>.dng"),
                 png=meta("flag: write images/<view>_raw.png (16-bit grey)"))
describe_foreign(ImagingParams, raw=meta("scenegen.imaging.RawOutput: the raw mosaic files; "
                                         "None = none", part=True, omit_default=True))
describe_foreign(SensorParams, black_level_clip=meta("flag", omit_default=True))
