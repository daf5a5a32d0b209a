"""Structured-light code and depth scores on hand-made maps."""
import math

import numpy as np

from recon_eval.metrics.structured_light import code_errors, depth_errors


def test_code_errors_by_hand():
    truth = np.array([[[3, 1], [4, 1]], [[5, 2], [-1, -1]]])
    lit = np.array([[True, True], [True, False]])
    dec = np.array([[[3.0, 1.0], [np.nan, np.nan]], [[6.2, 2.0], [7.0, 0.0]]])
    r = code_errors(dec, truth, lit, lengths_px=(8, 4))
    assert (r.n_lit, r.n_decoded) == (3, 2)
    assert math.isclose(r.completeness, 2 / 3) and math.isclose(r.agreement, 1 / 3)  # 6.2 names pixel 6
    assert math.isclose(r.max_px, 1.2) and math.isclose(r.mean_px, 0.6) and math.isclose(r.false_decode_frac, 1 / 3)
    assert r.n_clear == 0 and math.isnan(r.agreement_clear)
    clear = np.ones((2, 2, 2), bool)
    clear[1, 0, 1] = False  # the wrong pixel straddles a row edge: not scored by agreement_clear
    rc = code_errors(dec, truth, lit, lengths_px=(8, 4), clear=clear)
    assert rc.n_clear == 2 and math.isclose(rc.agreement_clear, 0.5)  # one clear pixel undecoded
    cont = code_errors(dec, truth, lit, lengths_px=(8, 4), truth_px=truth + 0.25)
    assert cont.against == "coordinates" and math.isclose(cont.max_px, math.hypot(0.95, 0.25))


def test_depth_errors_by_hand():
    gt = np.array([[1.0, 2.0], [3.0, np.inf]])
    est = np.array([[1.1, np.nan], [2.7, 5.0]])
    r = depth_errors(est, gt, np.ones((2, 2), bool), bound_m=np.full((2, 2), 0.2))
    assert (r.n_valid, r.n_estimated) == (3, 2) and math.isclose(r.completeness, 2 / 3)
    assert math.isclose(r.max_abs_m, 0.3) and math.isclose(r.rms_m, math.sqrt((0.01 + 0.09) / 2))
    assert r.within_bound_frac == 0.5
