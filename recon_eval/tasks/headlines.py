"""Headline metric names shared by a task's runs and its scoring command (docs/ci.md, "Metric
paths"): one name per number, so one gate file gates a method run with ``recon-eval run`` (built-in
or ``--command``) and the same estimate scored by hand with the command's ``--json``. The F's are
in :mod:`recon_eval.tasks.fmatrix_pair` (:func:`~recon_eval.tasks.fmatrix_pair.headline`)."""
from __future__ import annotations

#: Optical flow (:class:`recon_eval.metrics.flow.FlowResult` field -> headline name).
FLOW = {"epe_all_px": "epe_all_px", "epe_noc_px": "epe_noc_px", "epe_occ_px": "epe_occ_px",
        "fl_all_all_pct": "fl_all_all_pct", "s0_10_px": "s0_10_px"}
#: Depth maps (:class:`recon_eval.metrics.depth.DepthResult` field -> headline name); the
#: alignment's name in front (``median.abs_rel``) unless it is ``none``.
DEPTH = {"abs_rel": "abs_rel", "sq_rel_m": "sq_rel_m", "rmse_m": "rmse_m", "a1": "a1", "coverage": "coverage"}


def flow_headline(r) -> dict:
    """The headline of a :class:`~recon_eval.metrics.flow.FlowResult`."""
    return {name: getattr(r, field) for field, name in FLOW.items()}


def depth_headline(r, alignment: str) -> dict:
    """The headline of a :class:`~recon_eval.metrics.depth.DepthResult` under ``alignment``."""
    pre = "" if alignment == "none" else f"{alignment}."
    return {pre + name: getattr(r, field) for field, name in DEPTH.items()}
