"""The metrics: pure functions on arrays, each returning a frozen dataclass whose field names carry
units and provenance (docs/metrics.md). They never read files: readers, tasks, runners, reports
and the CLI call them.

:mod:`.align` (Umeyama, ICP, 15-DoF projective), :mod:`.calibration` (intrinsics, projection
difference, reprojection), :mod:`.depth` (Eigen), :mod:`.distances` (point and point-to-triangle),
:mod:`.dlt` (camera matrices), :mod:`.epipolar` (F, E, H), :mod:`.features` (repeatability, MMA,
matching score, precision / recall), :mod:`.pnp`, :mod:`.pointcloud` (Tanks and Temples, ETH3D,
DTU, Chamfer), :mod:`.poses` (APE, RPE, relative pose, mAA), :mod:`.stats`, :mod:`.stereo`
(KITTI D1, Middlebury, ETH3D), :mod:`.triangulation`.
"""
