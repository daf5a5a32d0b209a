"""What a sweep runs: each method as a :class:`SweepMethod` whose ``fit(x1, x2, seed, workdir)``
returns F (3, 3) or None (a failure, scored as such).

* ``survey-f-<name>``: the survey's estimators (:mod:`recon_eval.estimators.fundamental`), seeded
  with the trial's method seed;
* ``opencv-f-<flag>``: ``cv2.findFundamentalMat`` as the ``opencv-f-*`` runners call it
  (:func:`recon_eval.runners.twoview.fit_opencv_f`: their thresholds; OpenCV's own random
  generator, which is deterministic per call), but the 7-point flag (exactly seven points);
* a user's command (``--command`` or a methods file, :mod:`recon_eval.runners.external`): kind
  ``fmatrix`` with ``{matches}``: per trial it gets ``matches.npy`` (n, 4: x1 y1 x2 y2, undistorted
  px) and writes F to ``{out}``; a non-zero exit, a timeout or an unreadable F is a failure.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from recon_eval.errors import InputError
from recon_eval.estimators.fundamental import ESTIMATORS, estimate
from recon_eval.readers.matrix import read_matrix3
from recon_eval.runners import METHODS, Method
from recon_eval.runners.common import RunOutput
from recon_eval.runners.external import invoke
from recon_eval.runners.twoview import fit_opencv_f

SURVEY_PREFIX = "survey-f-"
#: The family of a method that is not the survey's.
OPENCV, YOURS = "opencv", "yours"


@dataclass(frozen=True)
class SweepMethod:
    name: str
    family: str  # linear / iterative / robust (the survey's), opencv, yours
    description: str
    params: dict
    fit: Callable  # (x1, x2, seed, workdir) -> F (3, 3) or None


def _survey(name: str) -> SweepMethod:
    e = ESTIMATORS[name]

    def fit(x1, x2, seed, workdir):
        F = estimate(name, x1, x2, seed=seed).F
        return F if np.all(np.isfinite(F)) else None

    return SweepMethod(SURVEY_PREFIX + name, e.family, f"{e.label} ({e.cites})",
                       {**dict(e.params), "seeded": e.seeded}, fit)


def _opencv(m: Method) -> SweepMethod:
    flag = dict(m.options)["flag"]
    if flag == "7point":
        raise InputError(f"sweep: {m.name} takes exactly seven points; sweep survey-f-seven-point instead")

    def fit(x1, x2, seed, workdir):
        F, _ = fit_opencv_f(flag, x1, x2)
        return None if F is None or np.asarray(F).shape != (3, 3) else np.asarray(F, np.float64)

    return SweepMethod(m.name, OPENCV, m.description, {"flag": flag}, fit)


def _external(m: Method, notes: RunOutput) -> SweepMethod:
    options = dict(m.options)
    if m.function != "fmatrix" or "{matches}" not in options["command"]:
        raise InputError(f"sweep: method {m.name!r} must be of kind fmatrix with {{matches}} in its command "
                         "(the sweep gives correspondences, not images)")

    def fit(x1, x2, seed, workdir: Path):
        workdir.mkdir(parents=True, exist_ok=True)
        mpath, fpath = workdir / "matches.npy", workdir / "F.txt"
        fpath.unlink(missing_ok=True)
        np.save(mpath, np.concatenate([x1, x2], axis=1))
        values = {"matches": str(mpath.resolve()), "out": str(fpath.resolve()),
                  "inliers": str((workdir / "inliers.npy").resolve()), "view1": "", "view2": "", "dataset": ""}
        item = str(workdir)
        if invoke({**options, "name": m.name}, values, workdir, item, notes) is not None:
            return None
        try:
            return read_matrix3(fpath, key="F")
        except InputError as exc:  # the method's failure, not bad input
            notes.notes[item] = {"failed": str(exc)}
            return None

    return SweepMethod(m.name, YOURS, m.description, {"command": options["command"]}, fit)


def resolve(names, declared: dict, notes: RunOutput) -> list[SweepMethod]:
    """The sweep methods of ``names`` (survey, OpenCV, or ``declared`` external methods); InputError
    for anything else."""
    out = []
    for name in names:
        if name.startswith(SURVEY_PREFIX) and name[len(SURVEY_PREFIX):] in ESTIMATORS:
            out.append(_survey(name[len(SURVEY_PREFIX):]))
        elif name in METHODS and METHODS[name].module == "twoview" and METHODS[name].function == "fundamental":
            out.append(_opencv(METHODS[name]))
        elif name in declared:
            out.append(_external(declared[name], notes))
        else:
            raise InputError(f"sweep: unknown method {name!r}: expected survey-f-<name> ({', '.join(ESTIMATORS)}), an "
                             "opencv-f-* method, or one of --command / --methods-file")
    if len({m.name for m in out}) != len(out):
        raise InputError("sweep: a method is named twice")
    return out


def builtin_resolver(kind: str, builtin: dict) -> Callable:
    """``resolve(names, declared, notes)`` of a sweep kind with only the built-in methods ``builtin``
    (name -> :class:`SweepMethod`, ``fit(trial, truth, seed, workdir)``): InputError for another name,
    a name given twice, or a user's command (the external contract's kinds are F's)."""

    def resolve(names, declared, notes) -> list[SweepMethod]:
        if declared:
            raise InputError(f"sweep --kind {kind}: --command / --methods-file take F methods only (--kind f): the "
                             f"external-command contract has no {kind} output")
        out = []
        for name in names:
            if name not in builtin:
                raise InputError(f"sweep --kind {kind}: unknown method {name!r}: expected one of {', '.join(builtin)}")
            out.append(builtin[name])
        if len(set(names)) != len(names):
            raise InputError("sweep: a method is named twice")
        return out

    return resolve


def all_survey() -> list[str]:
    return [SURVEY_PREFIX + n for n in ESTIMATORS]
