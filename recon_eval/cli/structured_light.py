"""``recon-eval codes``: a structured-light decoder's per-pixel code map against a dataset's
projector truth (docs/metrics.md, "Structured light"): agreement with the truth codes over the
lit pixels, completeness, code error in projector pixels (against the truth codes, or the
continuous truth coordinates with ``--continuous``); optionally its point cloud against the truth
points of the lit pixels (Tanks and Temples at ``--tau``, Chamfer)."""
from __future__ import annotations

import numpy as np

from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.pointcloud import chamfer, tanks_and_temples
from recon_eval.metrics.structured_light import code_errors
from recon_eval.readers.npy import read_npy
from recon_eval.readers.ply import read_geometry
from recon_eval.readers.scenegen_dataset import is_dataset
from recon_eval.readers.structured_light import projector_views


def arguments(p) -> None:
    p.add_argument("codes", help="code map .npy: (H, W, 2) projector (column, row) or (H, W) columns; "
                                 "NaN or negative where not decoded")
    p.add_argument("gt", help="the truth: a scenegen dataset folder with projector-lit views")
    p.add_argument("--view", help="the view the codes are of (default: the first projector-lit view)")
    p.add_argument("--continuous", action="store_true",
                   help="score the code error against the continuous truth coordinates (phase decoders)")
    p.add_argument("--cloud", metavar="PLY", help="the decoder's point cloud (world frame, metres)")
    p.add_argument("--tau", type=float, default=0.001, help="F-score threshold of --cloud, metres (default 0.001)")


def score(a):
    if not is_dataset(a.gt):
        raise InputError(f"{a.gt}: expected a scenegen dataset folder (manifest.json) as the truth")
    views = projector_views(a.gt, source="linear")
    pv = views[0] if a.view is None else next((v for v in views if v.view == a.view), None)
    if pv is None:
        raise InputError(f"--view {a.view!r}: not a projector-lit view (those: {', '.join(v.view for v in views)})")
    codes = read_npy(a.codes)
    if codes.ndim == 2:
        codes = codes[..., None]
    H, W = pv.lit.shape
    if codes.ndim != 3 or codes.shape[:2] != (H, W) or codes.shape[2] not in (1, 2):
        raise InputError(f"{a.codes}: expected a code map of shape ({H}, {W}, 2) or ({H}, {W}), got {codes.shape}")
    codes = np.where(codes >= -0.5, codes, np.nan)
    n = codes.shape[2]
    lengths = (pv.projector.width, pv.projector.height)[:n]
    res = {"codes": code_errors(codes, pv.truth_code[..., :n], pv.lit, lengths_px=lengths,
                                truth_px=pv.truth_uv[..., :n] if a.continuous else None, clear=pv.clear[..., :n])}
    if a.cloud:
        rec = read_geometry(a.cloud).vertices
        gt = pv.points_world[pv.lit & np.all(np.isfinite(pv.points_world), axis=2)]
        res["cloud"] = tanks_and_temples(rec, gt, a.tau)
        res["chamfer"] = chamfer(rec, gt)
    inputs = {"codes": a.codes, "gt": a.gt, "view": pv.view, "continuous": bool(a.continuous), "cloud": a.cloud}
    return inputs, res, no_figures


def metrics(a, res) -> dict:
    """``metrics`` of ``codes --json``: the names an ``sl-*`` run gives its pooled numbers (one
    view here; ``fscore``: that view's, the run's ``fscore_mean`` over its views)."""
    c = res["codes"]
    out = {"code_agreement": c.agreement, "code_agreement_decoded": c.agreement_decoded,
           "code_agreement_clear": c.agreement_clear,
           "code_completeness": c.completeness, "code_err_mean_px": c.mean_px}
    if "cloud" in res:
        out["fscore"] = res["cloud"].fscore
    return out


COMMANDS = {"codes": scored(arguments, score, metrics)}
