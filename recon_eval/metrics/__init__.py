"""The metrics: pure functions on arrays, each returning a frozen dataclass whose field names carry
units and provenance (docs/metrics.md). They never read files: readers, tasks, runners, reports
and the CLI call them.

:mod:`.align` (Umeyama, ICP, 15-DoF projective), :mod:`.calibration` (intrinsics, projection
difference, mrcal's projection_diff, reprojection), :mod:`.depth` (Eigen, SILog, iRMSE, MiDaS),
:mod:`.distances` (point and point-to-triangle, through :mod:`.mesh_bvh`), :mod:`.dlt` (camera
matrices), :mod:`.epipolar` (F, E, H), :mod:`.features` (repeatability, MMA, matching score,
precision / recall), :mod:`.flow` (EPE, KITTI Fl, Sintel bins, tracks), :mod:`.kitti_odometry`,
:mod:`.pnp`, :mod:`.pointcloud` (Tanks and Temples, ETH3D, DTU, Chamfer), :mod:`.poses` (APE, evo's
RPE, relative pose, mAA), :mod:`.sfm` (COLMAP's reprojection error and track length),
:mod:`.stats`, :mod:`.stereo` (KITTI D1, Middlebury, ETH3D), :mod:`.surfaces` (Occupancy Networks'
normal consistency and IoU), :mod:`.tnt` (the Tanks and Temples crop and curves),
:mod:`.triangulation`.
"""
