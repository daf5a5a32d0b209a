"""Estimators written in this project (numpy/scipy), for methods no maintained library offers:
:mod:`.fundamental` (the nineteen fundamental-matrix estimators of Armangue and Salvi's survey).
Pure functions of arrays: no dataset, no files; the runners (:mod:`recon_eval.runners`) run them
on datasets and score them."""
