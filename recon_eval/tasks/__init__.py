"""Protocols over a dataset that are neither metrics nor estimator runs: the triangulation task
(:mod:`.triangulation_task`), the per-pair feature evaluation (:mod:`.feature_eval`) and the
calibration-board truth lookup (:mod:`.board_truth`)."""
