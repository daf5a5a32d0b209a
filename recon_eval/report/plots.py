"""Figures for the HTML report, as PNG bytes (matplotlib, Agg backend, imported only here and only
when a report is asked for: ``recon-eval --help`` and the metrics never import it).

Each function takes plain arrays (never argparse namespaces) and returns one PNG. Conventions in
the pictures: images are drawn with pixel centres at integer coordinates (OpenCV), missing
values are grey, error colour scales are stated on their colour bars with units.
"""
from __future__ import annotations

import io

import numpy as np

from scenegen.geometry.color import to_uint8

_DPI = 100
MISSING_GREY = "#9e9e9e"


def _plt():
    import matplotlib  # heavy and optional: only a figure needs it

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt  # (matplotlib, after choosing the Agg backend)

    return plt


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI, bbox_inches="tight")
    _plt().close(fig)
    return buf.getvalue()


def _imshow(ax, img, title, cmap="viridis", vmin=None, vmax=None, label=None):
    import matplotlib  # heavy and optional: only a figure needs it

    cm = matplotlib.colormaps[cmap].copy()
    cm = cm.with_extremes(bad=MISSING_GREY)
    a = np.ma.masked_invalid(np.asarray(img, dtype=np.float64))
    h, w = a.shape
    im = ax.imshow(a, cmap=cm, vmin=vmin, vmax=vmax, interpolation="nearest", extent=(-0.5, w - 0.5, h - 0.5, -0.5))
    ax.set_title(title, fontsize=10)
    ax.set_xticks([])
    ax.set_yticks([])
    cb = ax.figure.colorbar(im, ax=ax, fraction=0.046, pad=0.03)
    if label:
        cb.set_label(label, fontsize=9)
    return im


def _finite_range(*arrays):
    v = np.concatenate([np.asarray(a, float)[np.isfinite(a)].ravel() for a in arrays] or [np.zeros(0)])
    if len(v) == 0:
        return 0.0, 1.0
    lo, hi = np.percentile(v, [1, 99])
    return float(lo), float(hi if hi > lo else lo + 1.0)


def map_error_figure(est, gt, *, title: str, unit: str, error_clip: float | None = None,
                     error_label: str | None = None) -> bytes:
    """Truth, estimate and |estimate - truth| heatmap of one depth or disparity map (H, W);
    NaN (missing) is grey. ``error_clip`` caps the error colour scale (default: 99th percentile)."""
    plt = _plt()
    est, gt = np.asarray(est, float), np.asarray(gt, float)
    err = np.abs(est - gt)
    err[~np.isfinite(gt)] = np.nan
    lo, hi = _finite_range(gt)
    emax = error_clip if error_clip else _finite_range(err)[1]
    h, w = gt.shape
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6 * h / max(w, 1) + 0.8))
    _imshow(axes[0], gt, "truth", vmin=lo, vmax=hi, label=unit)
    _imshow(axes[1], est, "estimate", vmin=lo, vmax=hi, label=unit)
    _imshow(axes[2], err, error_label or "|estimate - truth| (grey: missing)", cmap="inferno", vmin=0, vmax=emax,
            label=unit)
    fig.suptitle(title, fontsize=11)
    return _png(fig)


def cumulative_figure(curves: dict, *, xlabel: str, title: str, thresholds=(), xmax: float | None = None) -> bytes:
    """Cumulative error curves: for each name -> errors (N,), the fraction of items with error
    <= x. Failures (inf/NaN) count in N and never reach 1, so a curve's plateau shows them."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    top = 0.0
    for name, e in curves.items():
        e = np.asarray(e, float).ravel()
        n = len(e)
        if n == 0:
            continue
        f = np.sort(e[np.isfinite(e)])
        if len(f):
            top = max(top, float(f[-1]))
        y = np.arange(1, len(f) + 1) / n
        ax.step(np.r_[0.0, f], np.r_[0.0, y], where="post",
                label=f"{name} (n={n}, failed {n - len(f)})")
    xm = xmax if xmax is not None else (max(top, max(thresholds, default=0.0)) * 1.05 or 1.0)
    for t in thresholds:
        ax.axvline(t, color="k", lw=0.6, ls=":")
    ax.set_xlim(0, xm)
    ax.set_ylim(0, 1.02)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("fraction with error <= x")
    ax.set_title(title, fontsize=11)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return _png(fig)


def per_camera_figure(names, trans_err_m, rot_err_deg, *, title: str) -> bytes:
    """Per-camera APE bars (translation m, rotation deg); unregistered cameras (inf) are marked
    with a red x at the top and named in the legend."""
    plt = _plt()
    te, re_ = np.asarray(trans_err_m, float), np.asarray(rot_err_deg, float)
    n = len(names)
    x = np.arange(n)
    fig, axes = plt.subplots(2, 1, figsize=(max(6.4, 0.25 * n + 2), 5.5), sharex=True)
    for ax, e, lab in ((axes[0], te, "translation error (m)"), (axes[1], re_, "rotation error (deg)")):
        ok = np.isfinite(e)
        ax.bar(x[ok], e[ok], color="tab:blue")
        top = float(e[ok].max()) if ok.any() and e[ok].max() > 0 else 1.0
        if (~ok).any():
            ax.plot(x[~ok], np.full((~ok).sum(), top), "x", color="red", ms=9, mew=2, label="unregistered")
            ax.legend(fontsize=8)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3, axis="y")
    axes[1].set_xticks(x)
    axes[1].set_xticklabels([str(s) for s in names], rotation=90 if n > 8 else 0, fontsize=7)
    axes[0].set_title(title, fontsize=11)
    return _png(fig)


def precision_recall_figure(d_rec_to_gt, d_gt_to_rec, taus_m, *, tau_m: float, title: str) -> bytes:
    """Tanks and Temples precision, recall and F-score as functions of the threshold (strict <),
    computed from the distances at one downsampling (as the toolbox's plots do)."""
    plt = _plt()
    a, b = np.sort(np.asarray(d_rec_to_gt, float)), np.sort(np.asarray(d_gt_to_rec, float))
    t = np.asarray(taus_m, float)
    P = np.searchsorted(a, t, side="left") / max(len(a), 1)
    R = np.searchsorted(b, t, side="left") / max(len(b), 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        F = np.where(P + R > 0, 2 * P * R / (P + R), 0.0)
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    ax.plot(t * 1e3, P, label="precision")
    ax.plot(t * 1e3, R, label="recall")
    ax.plot(t * 1e3, F, label="F-score", lw=2)
    ax.axvline(tau_m * 1e3, color="k", ls=":", lw=0.8, label=f"tau = {tau_m * 1e3:g} mm")
    ax.set_xlabel("threshold tau (mm)")
    ax.set_ylabel("fraction")
    ax.set_ylim(0, 1.02)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(title, fontsize=11)
    return _png(fig)


def _line_segment(l, w, h):
    """End points of line l = (a, b, c) (a u + b v + c = 0) across [-0.5, w-0.5] x [-0.5, h-0.5]."""
    a, b, c = l
    pts = []
    for u in (-0.5, w - 0.5):
        if abs(b) > 1e-12:
            v = -(a * u + c) / b
            if -0.5 <= v <= h - 0.5:
                pts.append((u, v))
    for v in (-0.5, h - 0.5):
        if abs(a) > 1e-12:
            u = -(b * v + c) / a
            if -0.5 <= u <= w - 0.5:
                pts.append((u, v))
    return pts[:2] if len(pts) >= 2 else None


def epipolar_figure(img1, img2, F_est, x1, x2, *, F_gt=None, n_lines: int = 16, seed: int = 0,
                    title: str = "epipolar lines") -> bytes:
    """Both images with ``n_lines`` truth correspondences: in image 2 the points x2 and the lines
    F x1, in image 1 the points x1 and the lines F^T x2; the estimate's lines solid, the truth's
    (``F_gt``) dashed. Images (H, W[, 3]) uint8/uint16/float; pixels OpenCV."""
    plt = _plt()
    x1, x2 = np.asarray(x1, float), np.asarray(x2, float)
    pick = np.random.default_rng(seed).permutation(len(x1))[:n_lines]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5))
    colours = plt.get_cmap("tab20")(np.linspace(0, 1, max(len(pick), 1)))
    for ax, img, pts, other, Fm in ((axes[0], img1, x1, x2, "T"), (axes[1], img2, x2, x1, "")):
        im = np.asarray(img)
        if im.dtype == np.uint16:
            im = to_uint8(im)
        h, w = im.shape[:2]
        ax.imshow(im, cmap="gray" if im.ndim == 2 else None, extent=(-0.5, w - 0.5, h - 0.5, -0.5))
        for k, c in zip(pick, colours):
            for F, ls in ((F_est, "-"), (F_gt, "--")):
                if F is None:
                    continue
                F = np.asarray(F, float)
                l = (F.T if Fm == "T" else F) @ np.r_[other[k], 1.0]
                seg = _line_segment(l, w, h) if np.all(np.isfinite(l)) else None
                if seg:
                    (ua, va), (ub, vb) = seg
                    ax.plot([ua, ub], [va, vb], ls=ls, color=c, lw=1.2)
            ax.plot(*pts[k], "o", color=c, ms=5, mec="k")
        ax.set_xlim(-0.5, w - 0.5)
        ax.set_ylim(h - 0.5, -0.5)
        ax.set_xticks([])
        ax.set_yticks([])
    axes[0].set_title("image 1: points x1, lines F^T x2", fontsize=10)
    axes[1].set_title("image 2: points x2, lines F x1", fontsize=10)
    fig.suptitle(title + ("  (solid: estimate, dashed: truth)" if F_gt is not None else "  (estimate)"), fontsize=11)
    return _png(fig)


def field_figure(field, grid_u, grid_v, *, title: str, unit: str) -> bytes:
    """A scalar field over an image grid (calibration projection difference), with contours."""
    plt = _plt()
    f = np.asarray(field, float)
    fig, ax = plt.subplots(figsize=(7, 4.8))
    import matplotlib  # heavy and optional: only a figure needs it

    cm = matplotlib.colormaps["inferno"].copy()
    cm = cm.with_extremes(bad=MISSING_GREY)
    U, V = np.meshgrid(grid_u, grid_v)
    pc = ax.pcolormesh(U, V, np.ma.masked_invalid(f), cmap=cm, shading="nearest")
    if np.isfinite(f).sum() > 4 and np.nanmax(f) > np.nanmin(f):
        cs = ax.contour(U, V, np.ma.masked_invalid(f), colors="w", linewidths=0.6, levels=6)
        ax.clabel(cs, fontsize=7, fmt="%.3g")
    ax.set_xlim(-0.5, grid_u[-1] + 0.5)
    ax.set_ylim(grid_v[-1] + 0.5, -0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("u (px)")
    ax.set_ylabel("v (px)")
    fig.colorbar(pc, ax=ax, label=unit)
    ax.set_title(title, fontsize=11)
    return _png(fig)


def triangulation_angle_figure(curves: dict, *, title: str, points=None, guide=None, max_points: int = 4000,
                               seed: int = 0) -> bytes:
    """Triangulation error against the triangulation (baseline) angle, log-log: left the median
    error (m), right the median error over the truth depth, one marker per non-empty angle bin.

    ``curves``: label -> (angle_deg (K,), lo_deg (K,), hi_deg (K,), median_m (K,), median_rel (K,))
    of the bins: a marker at the median angle of the bin's points with a bar spanning [lo, hi).
    NaN / zero medians (empty bins, exact results) are left out of a log plot.
    ``points``: optional (angle_deg (N,), err_m (N,), rel_err (N,)) drawn faintly behind (at most
    ``max_points``, seeded sample; failures (inf) and exact zeros are left out of a log plot).
    ``guide``: optional (sigma_px, f_px): the first-order law ``sigma / (f theta)`` on the right
    (the depth error of a point seen from two views under angle theta, relative to its depth)."""
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    if points is not None:
        a, e, r = (np.asarray(v, float).ravel() for v in points)
        keep = np.flatnonzero(np.isfinite(e) & (e > 0) & (a > 0))
        if len(keep) > max_points:
            keep = np.sort(np.random.default_rng(seed).choice(keep, max_points, replace=False))
        for ax, y in ((axes[0], e), (axes[1], r)):
            ax.plot(a[keep], y[keep], ".", ms=1.5, color="0.75", zorder=1, label="points")
    for label, (x, lo, hi, med, rel) in curves.items():
        x, lo, hi, med, rel = (np.asarray(v, float) for v in (x, lo, hi, med, rel))
        for ax, y in ((axes[0], med), (axes[1], rel)):
            ok = np.isfinite(y) & (y > 0)
            left = np.maximum(lo[ok], x[ok] / 2)  # a log axis has no 0: a [0, hi) bin's bar starts at x / 2
            ax.errorbar(x[ok], y[ok], xerr=[x[ok] - left, hi[ok] - x[ok]], fmt="o-", ms=4, capsize=2, zorder=3,
                        label=label)
    if guide is not None:
        sigma_px, f_px = guide
        th = np.geomspace(0.2, 90.0, 50)
        axes[1].plot(th, sigma_px / (f_px * np.radians(th)), "k--", lw=0.8, zorder=2,
                     label=f"sigma / (f theta), sigma {sigma_px:g} px, f {f_px:g} px")
    for ax, yl in ((axes[0], "median error (m)"), (axes[1], "median error / truth depth")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("triangulation angle at the truth point (deg)")
        ax.set_ylabel(yl)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=11)
    return _png(fig)


def mma_curves_figure(curves: dict, *, title: str) -> bytes:
    """Mean matching accuracy against the pixel threshold (D2-Net, HPatches): for each label ->
    (thresholds_px (T,), mma (T,)) one curve; MMA is the fraction of putative matches within the
    threshold (<=), averaged over the image pairs."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    top = 1.0
    for label, (t, m) in curves.items():
        t = np.asarray(t, float)
        ax.plot(t, np.asarray(m, float), "o-", ms=3, label=label)
        top = max(top, float(t.max()))
    ax.set_xlim(0.5, top + 0.5)
    ax.set_ylim(0, 1.02)
    ax.set_xlabel("threshold (px)")
    ax.set_ylabel("MMA (fraction of matches <= threshold)")
    ax.set_title(title, fontsize=11)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return _png(fig)


def metric_vs_figure(x, curves: dict, *, xlabel: str, ylabel: str, title: str, xticklabels=None,
                     logx: bool = False) -> bytes:
    """Per-pair metrics against what varies along a series: ``x`` (P,) (angle, scale ratio, or the
    pair index with ``xticklabels``), ``curves`` label -> (P,) values in [0, 1]; NaN (undefined)
    values are left out of the line and marked with a red x at 0."""
    plt = _plt()
    x = np.asarray(x, float)
    order = np.argsort(x, kind="stable")
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for label, y in curves.items():
        y = np.asarray(y, float)[order]
        ok = np.isfinite(y)
        ax.plot(x[order][ok], y[ok], "o-", ms=4, label=label)
        if (~ok).any():
            ax.plot(x[order][~ok], np.zeros((~ok).sum()), "x", color="red", ms=8, mew=2)
    if logx:  # scale ratios: log axis, ticks at the pairs' own ratios
        ax.set_xscale("log", base=2)
        ax.minorticks_off()
        ax.set_xticks(x, [f"{v:.3g}" for v in x])
    if xticklabels is not None:
        ax.set_xticks(x)
        ax.set_xticklabels([str(s) for s in xticklabels], rotation=45 if len(x) > 4 else 0, fontsize=8, ha="right")
    ax.set_ylim(0, 1.02)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=11)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _png(fig)


def panels_figure(x, panels: dict, *, xlabel: str, ylabel: str, title: str, ceiling: float,
                  hline: float | None = None) -> bytes:
    """One log-y panel per group (a sweep's method families): ``panels`` group -> {label: (P,)
    values} against ``x`` (P,); values above ``ceiling`` or not finite (a failure, a broken estimate)
    are drawn at the ceiling with an open marker; ``hline`` a dashed threshold."""
    plt = _plt()
    x = np.asarray(x, float)
    n = max(len(panels), 1)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 3.8), sharey=True, squeeze=False)
    for ax, (group, curves) in zip(axes[0], panels.items()):
        for label, y in curves.items():
            y = np.asarray(y, float)
            over = ~(y <= ceiling)
            line, = ax.plot(x, np.where(over, ceiling, y), "o-", ms=4, label=label)
            if over.any():
                ax.plot(x[over], np.full(over.sum(), ceiling), "o", mfc="white", mec=line.get_color(), ms=7)
        if hline is not None:
            ax.axhline(hline, color="k", ls="--", lw=1)
        ax.set_yscale("log")
        ax.set_title(group, fontsize=10)
        ax.set_xlabel(xlabel)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel(ylabel)
    fig.suptitle(title, fontsize=11)
    return _png(fig)
