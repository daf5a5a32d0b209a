"""Camera models: projection, unprojection, validity (numpy; the arithmetic also runs in Dr.Jit).

Models and their parameter order (OpenCV's and COLMAP's):

* ``pinhole``: fx, fy, cx, cy, skew.
  ``u = fx x + skew y + cx``, ``v = fy y + cy`` with ``(x, y) = (X / Z, Y / Z)``.
* ``opencv``: pinhole + Brown-Conrady with OpenCV's rational and thin-prism terms, coefficients in
  OpenCV's order ``k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4`` (``cv2.projectPoints``;
  OpenCV's tilt terms tau_x, tau_y are not supported). With ``r2 = x^2 + y^2``::

      radial = (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3)
      xd = x radial + 2 p1 x y + p2 (r2 + 2 x^2) + s1 r2 + s2 r2^2
      yd = y radial + p1 (r2 + 2 y^2) + 2 p2 x y + s3 r2 + s4 r2^2
      u = fx xd + skew yd + cx,  v = fy yd + cy

* ``fisheye``: OpenCV fisheye = Kannala-Brandt with ``k1, k2, k3, k4``
  (``cv2.fisheye.projectPoints``; COLMAP ``OPENCV_FISHEYE``). With ``theta`` the angle between the
  ray and the optical axis, ``theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 +
  k4 theta^8)``, ``(xd, yd) = theta_d (X, Y) / |(X, Y)|``, then the pinhole with skew
  (``skew = fx * alpha`` in OpenCV's fisheye terms). ``theta = atan2(|(X, Y)|, Z)``, so rays
  beyond 90 degrees are projected too.

Pixels follow OpenCV (centre of the top-left pixel = (0, 0)), see :mod:`scenegen.geometry.conventions`.

One implementation of the arithmetic serves numpy (float64, the evaluator) and Dr.Jit (float32,
the renderer's rays): :mod:`.arith` uses only + - * /, sqrt, atan2, sin, cos and a select from
an ``ops`` object, with parameters passed as plain attributes (Python floats here, opaque Dr.Jit
floats in the Mitsuba sensor).

Modules: :mod:`.models` (the registry: one :class:`CameraModel` per model), :mod:`.arith` (the
formulas), :mod:`.validity` (fold limits, undistortion iteration counts), :mod:`.interop` (OpenCV
and COLMAP parameters), :mod:`.camera` (:class:`Camera`).

Undistortion is Newton's method with the analytic Jacobian, started at the distorted point, with
a fixed iteration count per camera: at construction the camera measures, over its whole pixel
border and an interior grid, how many iterations the worst pixel needs to reach
``validity.UNDISTORT_TOL_PX`` of reprojection residual in float64, and adds one. A fixed count keeps the
Dr.Jit kernel branch-free; the measured count is ``Camera.undistort_iterations``.

Validity: a distortion whose mapping folds over (Jacobian determinant <= 0) at a pixel inside the
image is rejected with ``ValueError`` naming that pixel. Points beyond the fold radius (the
monotonic region) project to NaN and are flagged invalid, as do points behind a non-fisheye
camera, and NaN inputs.
"""
from scenegen.geometry.camera.camera import Camera
from scenegen.geometry.camera.models import (
                                             ALL_COEFFS,
                                             FISHEYE_COEFFS,
                                             MODEL_NAMES,
                                             MODELS,
                                             OPENCV_COEFFS,
                                             CameraModel,
                                             camera_model,
                                             project_xyz,
                                             unproject_uv,
)
from scenegen.geometry.camera.validity import UNDISTORT_TOL_PX

__all__ = ["Camera", "CameraModel", "MODELS", "MODEL_NAMES", "OPENCV_COEFFS", "FISHEYE_COEFFS", "ALL_COEFFS",
           "camera_model", "project_xyz", "unproject_uv", "UNDISTORT_TOL_PX"]
