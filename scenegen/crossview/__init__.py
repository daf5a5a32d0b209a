"""Cross-view truth computed in numpy: what stereo, two-view and SfM estimators are scored against.

* :mod:`.correspondence`: dense correspondences i -> j through j's full camera model with a
  visible / occluded / out-of-frame state (visibility from a caller's function: the renderer's ray
  casts, :meth:`scenegen.render.scene.LoadedScene.visible_from`), and optical flow from them.
* :mod:`.matches`: putative match sets with labelled noise and outliers; labelled SIFT matches.
* :mod:`.targets`: per-view calibration-board corner truth.

Two-view geometry and rectification are in :mod:`scenegen.geometry` (:mod:`~scenegen.geometry.twoview`,
:mod:`~scenegen.geometry.rectify`); what is stored and how is the dataset's
(:mod:`scenegen.dataset.crossview`); the stage that writes it all is
:mod:`scenegen.pipeline.crossview`. Conventions: docs/crossview.md. Nothing here imports Mitsuba.
"""
