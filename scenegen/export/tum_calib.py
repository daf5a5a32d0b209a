"""A TUM RGB-D stream's camera calibration, the parameters a SLAM system needs to read its rgb/
and depth/ images (docs/crossview.md, exports):

* ``camera.txt``: ``fx fy cx cy k1 k2 p1 p2 k3``, the line the TUM RGB-D benchmark publishes for
  its cameras ("fx fy cx cy d0 d1 d2 d3 d4", OpenCV's distortion order), OpenCV pixels (the
  top-left pixel's centre is (0, 0): TUM's own cx = 319.5 for 640 px is that convention).
* ``orbslam.yaml``: an ORB-SLAM2 (and ORB-SLAM3 legacy) RGB-D settings file as OpenCV's
  FileStorage reads it (``%YAML:1.0``, ``Camera.fx`` ... ``Camera.k3``, size, fps,
  ``Camera.RGB: 1``, ``DepthMapFactor: 5000.0`` for our depth PNGs) with the ORB extractor values
  of ORB-SLAM2's own ``Examples/RGB-D/TUM1.yaml`` and ``Camera.bf`` = fx x 0.08 m (TUM1's 40 =
  517.3 px x 0.077 m, a Kinect's), so ``ThDepth: 40`` keeps points closer than 3.2 m "close".

The rgb/ images are as rendered (distorted by these coefficients). A camera this format cannot
hold (the fisheye model, OpenCV's rational or thin-prism terms, a skew) gets no files and a
reason instead.
"""
from __future__ import annotations

import numpy as np

from scenegen.export.common import fmt
from scenegen.geometry.camera.models import camera_model

#: ORB-SLAM's virtual RGB-D baseline (metres) behind Camera.bf.
ORB_BASELINE_M = 0.08
#: ORB-SLAM2's Examples/RGB-D/TUM1.yaml: the feature extractor and the close-depth threshold.
ORB_SETTINGS = (("ThDepth", "40.0"), ("ORBextractor.nFeatures", "1000"), ("ORBextractor.scaleFactor", "1.2"),
                ("ORBextractor.nLevels", "8"), ("ORBextractor.iniThFAST", "20"), ("ORBextractor.minThFAST", "7"))


def tum_parameters(camera) -> tuple[list[float] | None, str | None]:
    """([fx, fy, cx, cy, k1, k2, p1, p2, k3], None), or (None, why this camera has none)."""
    if camera_model(camera.model).opencv_fisheye:
        return None, f"the {camera.model} model (TUM's format holds a pinhole with k1 k2 p1 p2 k3)"
    if camera.skew != 0.0:
        return None, f"skew {camera.skew:g} px (TUM's format has none)"
    K, dist = camera.to_opencv()
    if len(dist) > 5:
        return None, "OpenCV rational or thin-prism coefficients (TUM's format holds k1 k2 p1 p2 k3)"
    d = np.zeros(5)
    d[:len(dist)] = dist
    return [K[0, 0], K[1, 1], K[0, 2], K[1, 2], *d], None


def _yaml_float(x: float) -> str:
    s = fmt(float(x))
    return s if any(c in s for c in ".en") else s + ".0"  # FileStorage reads '170' as an int


def calibration_files(stream: str, camera_name: str, camera, timestamps) -> dict[str, bytes] | str:
    """{file name: bytes} of a stream's calibration, or the reason it has none."""
    p, why = tum_parameters(camera)
    if p is None:
        return why
    head = (f"# scenegen truth: stream {stream}, camera {camera_name!r}, {camera.width}x{camera.height} px, "
            "OpenCV pixels (top-left pixel centre (0, 0)); rgb/ is distorted by these coefficients, "
            "depth/ is z-depth on the same pixels")
    txt = f"{head}\n# fx fy cx cy k1 k2 p1 p2 k3 (TUM RGB-D: fx fy cx cy d0 d1 d2 d3 d4)\n" + " ".join(map(fmt, p)) + "\n"
    dt = np.diff(np.asarray(timestamps, float))
    keys = ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")
    rows = [f"Camera.{k}: {_yaml_float(v)}" for k, v in zip(keys, p)]
    rows += [f"Camera.width: {camera.width}", f"Camera.height: {camera.height}"]
    if len(dt):  # one frame: ORB-SLAM takes its default of 30
        rows.append(f"Camera.fps: {_yaml_float(1.0 / float(np.median(dt)))}")
    rows += ["Camera.RGB: 1", f"Camera.bf: {_yaml_float(p[0] * ORB_BASELINE_M)}", "DepthMapFactor: 5000.0"]
    rows += [f"{k}: {v}" for k, v in ORB_SETTINGS]
    yml = ("%YAML:1.0\n" + head + "\n# ORB-SLAM2 RGB-D settings; ORBextractor and ThDepth: ORB-SLAM2's TUM1.yaml, "
           f"Camera.bf = fx x {ORB_BASELINE_M} m\n" + "\n".join(rows) + "\n")
    return {"camera.txt": txt.encode(), "orbslam.yaml": yml.encode()}
