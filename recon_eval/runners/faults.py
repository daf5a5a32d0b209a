"""Deliberately broken estimators: a correct runner with one planted error in its raw output, so
that the gates and the baseline comparison can be shown to catch it (docs/ci.md). They are listed
in :data:`recon_eval.runners.FAULTS`, apart from the production methods, and run by name like them.

* ``broken-calib-cx``: checkerboard calibration whose written camera matrix has cx moved by
  :data:`CX_SHIFT_PX`;
* ``broken-f-transposed``: RANSAC fundamental matrices written transposed (F^T maps view j's
  points to view i's lines: the wrong direction).
"""
from __future__ import annotations

import numpy as np

from recon_eval.runners import calibration, twoview
from recon_eval.runners.common import RunOutput

#: The planted principal-point error of ``broken-calib-cx``, px.
CX_SHIFT_PX = 2.0


def shift_cx(K: np.ndarray) -> np.ndarray:
    K = K.copy()
    K[0, 2] += CX_SHIFT_PX
    return K


def calib_cx(ds, out_dir, options=None) -> RunOutput:
    """Checkerboard calibration, cx + CX_SHIFT_PX in the written camera matrix."""
    return calibration.calibrate(ds, out_dir, board_kind="checkerboard", fisheye=False, transform_K=shift_cx)


def f_transposed(ds, out_dir, options) -> RunOutput:
    """cv2.findFundamentalMat with ``options["flag"]``, every estimate written transposed."""
    return twoview.fundamental(ds, out_dir, options, transform_F=np.transpose)
