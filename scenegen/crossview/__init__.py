"""Cross-view truth: what stereo, two-view and SfM estimators are scored against.

One idea per module:

* :mod:`.twoview`: relative pose, E, F (on undistorted pixels), epipoles, plane homographies,
  Sampson error (numpy only).
* :mod:`.correspondence`: dense correspondences i -> j through j's full camera model with a
  visible / occluded / out-of-frame state (numpy; visibility comes from a caller's function).
* :mod:`.raycast`: the Mitsuba ray casts behind visibility (occlusion) and sub-pixel truth.
* :mod:`.rectify`: Bouguet rectification of a stereo pair (as ``cv2.stereoRectify``) and the
  rectification maps.
* :mod:`.disparity`: disparity from depth, PFM and KITTI PNG16 files.
* :mod:`.flow`: Middlebury ``.flo`` files.
* :mod:`.matches`: putative match sets with labelled noise and outliers; labelled SIFT matches.
* :mod:`.targets`: per-view calibration-board corner truth.
* :mod:`.stage`: the pipeline stage that writes all of it into a dataset.

Conventions are the project's (:mod:`scenegen.geometry.conventions`); the cross-view ones are documented in
``docs/crossview.md``. Only :mod:`.raycast` and :mod:`.stage` import Mitsuba (lazily).
"""
