"""Orchestration: a spec to a dataset (:mod:`.run`), one view (:mod:`.view`), the cross-view stage
(:mod:`.crossview`, :mod:`.stereo`, :mod:`.pairs`), variants and Dask workers (:mod:`.batch`,
:mod:`.distributed`), progress (:mod:`.progress`). A leaf: nothing in scenegen imports it back
(only the command line)."""
