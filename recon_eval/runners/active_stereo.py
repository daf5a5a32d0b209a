"""OpenCV StereoSGBM on the IR pair of an active stereo frame (RealSense-like: two monochrome IR
cameras and a dot projector; ``crossview/stereo/<left view>/ir_left.png, ir_right.png``,
docs/dataset_format.md, "Active IR stereo"), the projector on (``opencv-sgbm-ir``) or off
(``opencv-sgbm-ir-off``: the same cameras and ambient light without the dots, what the pattern buys
on textureless surfaces).

The matcher is :mod:`recon_eval.runners.stereo`'s StereoSGBM with its settings (numDisparities
from the width only, block 5, P1/P2 for one channel), on the IR images as stored (grey, no
conversion). Scored as that runner scores (Middlebury v3 over the non-occluded and over all
pixels with truth, the median signed error), plus the same metrics over the pixels the IR invalid
mask calls valid (``ir_invalid == 0``: lit by the projector, seen by both cameras, in the depth
range): ``bad_2_0_valid_pct`` is the headline.
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.stereo import two_view_metrics
from recon_eval.readers.pfm import read_pfm
from recon_eval.runners import stereo
from recon_eval.runners.common import RunOutput
from scenegen.dataset.codecs import write_pfm
from scenegen.dataset.layout import stereo_path


def _sgbm_ir(projector: bool):
    """``compute(ds, left, path, out)`` for :func:`recon_eval.runners.stereo.run`: SGBM on the IR pair."""
    def compute(ds, left, path, out) -> None:
        if not (ds.root / stereo_path(left, "ir", "left")).is_file():
            raise NotApplicable(f"{ds.root}: stereo frame {left!r} has no IR pair (a rig with a projector, "
                                "docs/dataset_format.md 'Active IR stereo')")
        L, R = ds.stereo_ir_images(left, projector)
        if L.dtype != np.uint8:  # SGBM takes 8-bit images
            L, R = (np.rint(a / 257.0).astype(np.uint8) for a in (L, R))
        m, nd = stereo.sgbm_matcher(L.shape[1], 1)
        raw = m.compute(L, R).astype(np.float64) / 16.0  # fixed point, 4 fractional bits
        write_pfm(path, np.where(raw >= 0, raw, np.nan))  # invalid = minDisparity - 1 (/16) -> missing
        out.notes[f"{left}.num_disparities"] = nd
        out.notes["projector"] = "on" if projector else "off"
    return compute


def run(ds, out_dir, options) -> RunOutput:
    """SGBM on every active frame's IR pair (module docstring), scored."""
    out = stereo.run(ds, out_dir, options, compute=_sgbm_ir(options["projector"] == "on"))
    lefts = ds.stereo_left_views()
    ests = [read_pfm(out_dir / f"disparity/{left}.pfm") for left in lefts]
    gts = [ds.stereo_disparity(left) for left in lefts]
    valid = [ds.stereo_ir_invalid(left) == 0 for left in lefts]
    res = two_view_metrics(ests, gts, valid, benchmark="middlebury_v3")
    out.results["middlebury_ir_valid"] = res
    out.metrics.update({"bad_2_0_valid_pct": res.bad_2_0_pct, "bad_1_0_valid_pct": res.bad_1_0_pct,
                        "invalid_valid_pct": res.invalid_pct, "avgerr_valid_px": res.avgerr_px,
                        "valid_px_pct": float(100.0 * np.mean(np.concatenate([v.ravel() for v in valid])))})
    return out
