"""Continuous integration of estimators (docs/ci.md): accuracy gates over run results
(:mod:`.gates`) and the leaderboard over datasets and methods (:mod:`.leaderboard`)."""
