"""Cross-view truth to write (the optional ``crossview:`` section, docs/crossview.md)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Union

from scenegen.errors import Where
from scenegen.spec.model.meta import SEED_MAX, param, part, where_field

CROSSVIEW_PAIR_MODES = ("consecutive", "all", "none")
_FRACTION = "fraction"


@dataclass(frozen=True, kw_only=True)
class MatchSetSpec:
    """Putative match sets sampled from visible truth correspondences (per selected pair)."""

    count: int = param(1000, unit="matches per pair", lo=1)  # fewer when fewer pixels are visible
    sigma_px: float = param(0.5, unit="pixels", lo=0.0)  # Gaussian noise of inliers, per
    # coordinate of both points
    outlier_fraction: float = param(0.2, unit=_FRACTION, lo=0.0, hi=1.0, hi_open=True)  # share
    # of outliers
    near_miss_fraction: float = param(0.5, unit=_FRACTION, lo=0.0, hi=1.0)  # share of the
    # outliers that are near misses
    near_miss_px: tuple[float, float] = param((4.0, 16.0), unit="min and max distance, pixels",
                                              lo=0.0, lo_open=True)  # near-miss distance range
    # from the truth
    seed: int = param(0, unit="seed", label="", lo=0, hi=SEED_MAX,
                      derived="seed32(scene seed, field path)")
    where: Where | None = where_field()


@dataclass(frozen=True, kw_only=True)
class CrossviewSpec:
    """What cross-view truth to write (the optional top-level ``crossview:`` section)."""

    pairs: Union[str, tuple[tuple[str, str], ...]] = param(
        "consecutive", unit="pair selection (or a list of pairs)", choices=CROSSVIEW_PAIR_MODES)
    # or explicit (view_a, view_b) names; dense correspondences both ways + two-view geometry
    flow: bool = param(True, unit="flag")  # Middlebury .flo flow between consecutive frames of
    # each camera stream
    stereo: bool = param(True, unit="flag")  # rectified renders, disparity and maps for every
    # stereo-rig frame (in a sequence also the scene flow truth on the rectified grid)
    matches: MatchSetSpec | None = part(None, unit="synthetic labelled match sets per pair "
                                                   "(None = off)")
    sift: bool = param(False, unit="flag")  # OpenCV SIFT matches per pair, labelled against the
    # truth
    sift_ratio: float = param(0.8, unit="Lowe ratio", lo=0.0, lo_open=True, hi=1.0)  # Lowe's
    # ratio test threshold
    sift_inlier_px: float = param(2.0, unit="pixels", lo=0.0, lo_open=True)  # a SIFT match is
    # an inlier within this distance of the truth
    targets: bool = param(True, unit="flag")  # per-view calibration-board corner truth (when
    # the scene has boards)
    ir_depth_range_m: tuple[float, float] = param((0.0, 1000.0), unit="min and max depth z, metres", lo=0.0,
                                                  omit_default=True)  # active IR stereo: a
    # pixel whose depth lies outside is invalid, out of range (docs/dataset_format.md)
    where: Where | None = where_field()
