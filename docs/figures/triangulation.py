"""Figure: triangulation error against the triangulation (baseline) angle at sigma = 1 px
(writes docs/figures/triangulation.png and prints the tables of docs/metrics.md, "Triangulation").

Renders scenes/triangulation_baselines.yaml at its own settings into a temporary folder (Mitsuba),
writes the triangulation task of its six pairs (reference view against views at about 1, 2, 5,
10, 20 and 40 degrees; 2000 visible truth points per pair, sigma 1 px, seed 0), triangulates it
with OpenCV's triangulatePoints (the reference) and scores it, all through the task files, as
``recon-eval triangulation-task`` and ``recon-eval triangulation`` do.

    .venv/bin/python docs/figures/triangulation.py [--dataset DIR]   # DIR: an existing render
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from recon_eval.report import plots
from recon_eval.tasks import triangulation_task as tt
from recon_eval.metrics.dlt import decompose_projection
from recon_eval.readers.scenegen_dataset import read_dataset

ROOT = Path(__file__).resolve().parents[2]
SIGMA_PX = 1.0
COUNT = 2000
SEED = 0


def score(dataset: Path, work: Path, sigma: float):
    ds = read_dataset(dataset)
    pairs = [tt.build_pair(ds, v1, v2, sigma, COUNT, SEED) for v1, v2 in tt.dataset_pairs(ds)[0]]
    tt.write_task(work / "task", pairs, {"dataset": str(dataset), "sigma_px": sigma, "seed": SEED, "count": COUNT})
    _, pairs = tt.read_task(work / "task")
    for tp in pairs:
        tt.write_points(work / "est" / f"{tp.name}.txt", tt.reference_points(tp))
    est, _ = tt.read_estimates(work / "est", pairs)
    return pairs, tt.score_task(pairs, est)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dataset", type=Path, help="an existing render of the scene (default: render it)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        dataset = a.dataset
        if dataset is None:
            from scenegen.pipeline.run import render_spec

            dataset = tmp / "data"
            s = render_spec(ROOT / "scenes/triangulation_baselines.yaml", dataset, progress=False)
            print(f"rendered {dataset}: {s}")
        pairs, res = score(dataset, tmp, SIGMA_PX)
        _, res0 = score(dataset, tmp / "noise_free", 0.0)
    pooled = res["all_pairs"]
    print(f"noise-free: largest error / depth {res0['all_pairs'].rel_err.max():.2g}")
    print("| pair | median angle (deg) | median error (m) | median error / depth |\n|---|---|---|---|")
    for tp in pairs:
        s = res[tp.name]
        print(f"| {tp.view1} / {tp.view2} | {np.median(s.angle_deg):.3g} | {s.median_m:.4g} | {s.median_rel:.3g} |")
    print("| angle (deg) | n | median error (m) | median error / depth |\n|---|---|---|---|")
    for b in pooled.bins:
        if b.n:
            print(f"| [{b.lo_deg:g}, {b.hi_deg:g}) | {b.n} | {b.median_m:.4g} | {b.median_rel:.3g} |")
    fx = float(np.median([decompose_projection(tp.P1)[0][0, 0] for tp in pairs]))
    png = plots.triangulation_angle_figure(
        {"cv2.triangulatePoints": tt.bin_curve(pooled)},
        title=f"scenes/triangulation_baselines.yaml: 6 pairs x {COUNT} truth points, sigma {SIGMA_PX:g} px",
        points=(pooled.angle_deg, pooled.err_m, pooled.rel_err), guide=(SIGMA_PX, fx))
    out = ROOT / "docs/figures/triangulation.png"
    out.write_bytes(png)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
