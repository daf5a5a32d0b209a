"""The nineteen fundamental-matrix estimators of Armangue and Salvi, "Overall view regarding
fundamental matrix estimation", Image and Vision Computing 21(2), 2003 (docs/fmatrix_survey.md),
in numpy/scipy, one module per family:

* :mod:`.linear`: 7-point, 8-point with least squares, 8-point with eigen analysis, rank-2
  constraint;
* :mod:`.iterative`: iterative linear, Newton-Raphson, minimisation in parameter space, gradient
  with least squares and with eigen analysis; :mod:`.fns`: FNS, CFNS;
* :mod:`.mestimators`: M-estimators with least squares, with eigen analysis, Torr's;
  :mod:`.sampling`: LMedS with least squares and with eigen analysis, RANSAC, MLESAC, MAPSAC.

:data:`ESTIMATORS` is the registry (name -> :class:`Estimator`: family, function, the parameters
it runs with, what it cites, the OpenCV flag of the same method when there is one);
:func:`estimate` runs one by name on (N, 2) undistorted pixel correspondences ``x2^T F x1 = 0``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from recon_eval.errors import InputError
from recon_eval.estimators.fundamental import fns, iterative, linear, mestimators, sampling
from recon_eval.estimators.fundamental.common import Estimate

#: The survey's three families, in its order.
FAMILIES = ("linear", "iterative", "robust")
#: Robust parameters (px): the noise scale the sampling methods assume, and RANSAC's threshold on
#: the Sampson distance (1.96 sigma: 95 % of Gaussian inliers).
SIGMA_PX = 1.0
RANSAC_THRESHOLD_PX = 2.0
CONFIDENCE = 0.999
MAX_SAMPLES = 5000


@dataclass(frozen=True)
class Estimator:
    name: str
    family: str  # one of FAMILIES
    label: str  # the survey's name for it
    function: Callable  # (x1, x2, **params) -> Estimate
    params: tuple = ()  # (key, value) pairs passed to the function (seed added when ``seeded``)
    seeded: bool = False  # takes ``seed``
    cites: str = ""
    opencv: str | None = None  # the cv2.findFundamentalMat flag of the same method


def _e(name, family, label, function, cites, opencv=None, seeded=False, **params):
    return Estimator(name, family, label, function, tuple(sorted(params.items())), seeded, cites, opencv)


_SAMPLING = {"confidence": CONFIDENCE, "max_iter": MAX_SAMPLES}

ESTIMATORS: dict[str, Estimator] = {e.name: e for e in [
    _e("seven-point", "linear", "7-point", linear.seven_point, "H&Z sec. 11.1.2", "7point"),
    _e("eight-point-ls", "linear", "8-point LS", linear.eight_point_ls, "Hartley 1997; H&Z Alg. 11.1 (F33 = 1)"),
    _e("eight-point-eigen", "linear", "8-point eigen", linear.eight_point_eigen, "Hartley 1997; H&Z Alg. 11.1",
       "8point"),
    _e("rank2-algebraic", "linear", "rank-2 constraint", linear.rank2_algebraic, "H&Z Alg. 11.2, sec. 11.3"),
    _e("iterative-linear", "iterative", "iterative linear", iterative.iterative_linear,
       "Luong and Faugeras 1996; Zhang 1998 (distances to epipolar lines)"),
    _e("newton-raphson", "iterative", "Newton-Raphson", iterative.newton_raphson, "Sampson residuals, Gauss-Newton"),
    _e("parameter-space", "iterative", "minimisation in parameter space", iterative.parameter_space,
       "Luong and Faugeras 1996; Zhang 1998 (epipole parameterisation)"),
    _e("gradient-ls", "iterative", "gradient LS", iterative.gradient_ls, "Zhang 1998 (gradient weighting), F33 = 1"),
    _e("gradient-eigen", "iterative", "gradient eigen", iterative.gradient_eigen, "Zhang 1998 (gradient weighting), |f| = 1"),
    _e("fns", "iterative", "FNS", fns.fns, "Chojnacki et al., PAMI 22(11), 2000"),
    _e("cfns", "iterative", "CFNS", fns.cfns, "Chojnacki et al. 2002; IVC 22(2), 2004"),
    _e("m-estimator-ls", "robust", "M-estimator LS", mestimators.m_ls, "Huber; Zhang 1998 (M-estimators)"),
    _e("m-estimator-eigen", "robust", "M-estimator eigen", mestimators.m_eigen, "Huber; Zhang 1998 (M-estimators)"),
    _e("m-estimator-torr", "robust", "M-estimator Torr", mestimators.m_torr, "Torr and Murray, IJCV 24(3), 1997"),
    _e("lmeds-ls", "robust", "LMedS LS", sampling.lmeds_ls, "Rousseeuw 1984; Zhang 1998 (LMedS)", seeded=True,
       **_SAMPLING),
    _e("lmeds-eigen", "robust", "LMedS eigen", sampling.lmeds_eigen, "Rousseeuw 1984; Zhang 1998 (LMedS)", "lmeds",
       seeded=True, **_SAMPLING),
    _e("ransac", "robust", "RANSAC", sampling.ransac, "Fischler and Bolles 1981; H&Z sec. 4.7", "ransac", seeded=True,
       threshold_px=RANSAC_THRESHOLD_PX, **_SAMPLING),
    _e("mlesac", "robust", "MLESAC", sampling.mlesac, "Torr and Zisserman, CVIU 78(1), 2000", seeded=True,
       sigma_px=SIGMA_PX, **_SAMPLING),
    _e("mapsac", "robust", "MAPSAC", sampling.mapsac, "Torr, IJCV 50(1), 2002", seeded=True, sigma_px=SIGMA_PX,
       **_SAMPLING),
]}


def estimator(name: str) -> Estimator:
    if name not in ESTIMATORS:
        raise InputError(f"unknown F estimator {name!r}; known: {', '.join(ESTIMATORS)}")
    return ESTIMATORS[name]


def estimate(name: str, x1, x2, *, seed: int = 0) -> Estimate:
    """Run estimator ``name`` on correspondences x1 <-> x2 (N, 2) undistorted pixels."""
    e = estimator(name)
    kwargs = dict(e.params)
    if e.seeded:
        kwargs["seed"] = seed
    return e.function(x1, x2, **kwargs)


__all__ = ["ESTIMATORS", "FAMILIES", "Estimate", "Estimator", "estimate", "estimator"]
