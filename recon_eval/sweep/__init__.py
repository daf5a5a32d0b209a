"""Robustness sweeps of fundamental-matrix estimators on a dataset's exact truth
(``recon-eval sweep``, docs/fmatrix_survey.md): :mod:`.draw` (seeded trials: truth
correspondences, Gaussian noise, outliers), :mod:`.methods` (what can be swept: the survey's
estimators, OpenCV's, a user's command line), :mod:`.run` (the cells), :mod:`.summary` (per-cell
statistics and breakdown points)."""
