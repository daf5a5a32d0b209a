"""LiDAR presets from public sensor specifications (docs/scene_spec.md, "LiDARs"): the values a
``preset:`` gives the keys of a ``lidars:`` entry that are not written. Angles in degrees in our
convention (:mod:`scenegen.geometry.lidar`: azimuth counter-clockwise from +x, seen from above).

* ``ouster_os1_64``: Ouster OS1-64 (gen 1), 2048 x 10 mode. ``beam_altitude_angles`` and
  ``beam_azimuth_angles`` are the gen-1 defaults of the Ouster SDK (ouster-lidar/ouster_example,
  ``gen1_altitude_angles`` / ``gen1_azimuth_angles``). Ouster's own formula
  (``theta = theta_encoder + theta_azimuth`` with ``theta_encoder = 2 pi (1 - j / 2048)`` and
  ``theta_azimuth = -2 pi beam_azimuth_angles / 360``) is our clockwise column order with
  ``azimuth_offset = -beam_azimuth_angle``. All 64 channels of a column fire at once (one
  timestamp per measurement block). The 15.8 mm ``lidar_origin_to_beam_origin`` is not modelled:
  every beam leaves the LiDAR origin.
* ``velodyne_hdl64e``: Velodyne HDL-64E S2, nominal angles (the user's manual: the upper block
  of 32 lasers from +2 to -8.33 degrees at 1/3 degree spacing, the lower block from -8.83 to
  -24.33 degrees at 1/2 degree; each unit ships its own calibration), 10 Hz, 2048 columns (our
  choice: the manual's 0.1728 degree resolution at 10 Hz is 2083). The two blocks fire at the
  same time, each block one laser at a time: laser i and i + 32 fire i / 32 of a column after
  its start.
* ``velodyne_vlp16``: Velodyne VLP-16 (Puck), the user's manual's laser table (laser id ->
  elevation -15, 1, -13, 3, ... 15 degrees) and firing timing (one laser every 2.304 us in id
  order), 10 Hz, 1800 columns (0.2 degree; the manual's 55.296 us firing cycle gives 1808.4).
"""
from __future__ import annotations

import numpy as np

_OS1_ALTITUDE = (
    16.611, 16.084, 15.557, 15.029, 14.502, 13.975, 13.447, 12.920, 12.393, 11.865, 11.338, 10.811, 10.283, 9.756,
    9.229, 8.701, 8.174, 7.646, 7.119, 6.592, 6.064, 5.537, 5.010, 4.482, 3.955, 3.428, 2.900, 2.373, 1.846, 1.318,
    0.791, 0.264, -0.264, -0.791, -1.318, -1.846, -2.373, -2.900, -3.428, -3.955, -4.482, -5.010, -5.537, -6.064,
    -6.592, -7.119, -7.646, -8.174, -8.701, -9.229, -9.756, -10.283, -10.811, -11.338, -11.865, -12.393, -12.920,
    -13.447, -13.975, -14.502, -15.029, -15.557, -16.084, -16.611)
_OS1_AZIMUTH = (3.164, 1.055, -1.055, -3.164) * 16
_HDL64_ELEVATION = tuple(round(2.0 - i / 3.0, 6) for i in range(32)) + tuple(-8.83 - i / 2.0 for i in range(32))
_HDL64_COLUMN_S = 1.0 / (2048 * 10.0)
_VLP16_ELEVATION = (-15.0, 1.0, -13.0, 3.0, -11.0, 5.0, -9.0, 7.0, -7.0, 9.0, -5.0, 11.0, -3.0, 13.0, -1.0, 15.0)

#: Preset name -> {field of scenegen.spec.sensors.lidar.LidarSpec: value}.
LIDAR_PRESETS: dict[str, dict] = {
    "ouster_os1_64": {
        "pattern": "spinning", "elevations_deg": _OS1_ALTITUDE, "azimuth_offsets_deg": tuple(-a for a in _OS1_AZIMUTH),
        "firing_offsets_us": (0.0,) * 64, "columns": 2048, "rate_hz": 10.0, "clockwise": True,
        "min_range_m": 0.8, "max_range_m": 120.0},
    "velodyne_hdl64e": {
        "pattern": "spinning", "elevations_deg": _HDL64_ELEVATION, "azimuth_offsets_deg": (0.0,) * 64,
        "firing_offsets_us": tuple(float(np.round((i % 32) * _HDL64_COLUMN_S / 32 * 1e6, 6)) for i in range(64)),
        "columns": 2048, "rate_hz": 10.0, "clockwise": True, "min_range_m": 0.9, "max_range_m": 120.0},
    "velodyne_vlp16": {
        "pattern": "spinning", "elevations_deg": _VLP16_ELEVATION, "azimuth_offsets_deg": (0.0,) * 16,
        "firing_offsets_us": tuple(round(2.304 * i, 6) for i in range(16)), "columns": 1800, "rate_hz": 10.0,
        "clockwise": True, "min_range_m": 0.5, "max_range_m": 100.0},
}
