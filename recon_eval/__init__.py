"""recon_eval: score third-party 3D-vision results against exact synthetic truth.

Every metric is a pure function returning a frozen dataclass whose field names carry units
(``rot_err_deg``, ``rmse_m``, ``tau_m``) and provenance (alignment, distance definition, comparison
operator). Definitions follow the reference benchmarks as summarised in ``docs/metrics.md``.

Conventions (shared with :mod:`scenegen.geometry.conventions`): OpenCV camera axes (+x right, +y down,
+z forward); poses are ``cam_from_world`` pairs ``(R (3, 3), t (3,))`` with
``x_cam = R @ x_world + t``; metres; radians inside, degrees only in result fields named ``*_deg``;
pixel centre of the top-left pixel at (0, 0).

This package never imports Mitsuba or Dr.Jit.
"""
__version__ = "0.1.0"

#: Version of the JSON result schema written by :mod:`recon_eval.cli` (see docs/metrics.md).
SCHEMA_VERSION = "1.0"
