"""Figure: OpenCV keypoints and descriptors on the feature scenes (writes docs/figures/features_mma.png).

Renders scenes/features_planar.yaml and scenes/features_3d.yaml at their own settings (or reuses
the datasets already under --data), runs the four runners opencv-features-{sift,orb,akaze,brisk}
on each (raw output in recon_eval's feature format, scored from those files; docs/features.md),
then draws one column per series: on top MMA against the pixel threshold (D2-Net style, mean over
the series' pairs), below MMA@3 against what the series varies (relative rotation, scale ratio,
or the pair for an illumination series). Prints the headline numbers as a Markdown table.

    .venv/bin/python docs/figures/features.py [--data out/features_figure] [--scenes SPEC ...]
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SCENES = (ROOT / "scenes/features_planar.yaml", ROOT / "scenes/features_3d.yaml")
METHODS = ("sift", "orb", "akaze", "brisk")
OUT = ROOT / "docs/figures/features_mma.png"


def render(spec: Path, data: Path) -> Path:
    from scenegen.pipeline.run import render_spec

    out = data / spec.stem
    if (out / "crossview" / "index.json").is_file():
        print(f"{spec.name}: reusing {out}")
        return out
    t0 = time.perf_counter()
    render_spec(spec, out, progress=False)
    print(f"{spec.name}: rendered in {time.perf_counter() - t0:.1f} s")
    return out


def run_all(dataset: Path, data: Path) -> dict:
    """method -> run document (result.json)."""
    from recon_eval.runners import run_method

    docs = {}
    for m in METHODS:
        t0 = time.perf_counter()
        docs[m] = run_method(f"opencv-features-{m}", dataset, data / "runs" / dataset.name / m)
        print(f"  {m:6s} {time.perf_counter() - t0:6.2f} s")
    return docs


def series_of(doc: dict) -> list:
    """(series name, kind, [pair results]) in the run's order."""
    res = doc["results"]
    out = []
    for key, s in res.items():
        if key.startswith("series."):
            out.append((s["series"], s["kind"], [res[f"pair.{p}"] for p in s["pairs"]]))
    return out


def _x(kind: str, pairs: list):
    if kind == "viewpoint":
        return [p["description"]["rotation_deg"] for p in pairs], "relative rotation (deg)", None
    if kind == "scale":
        return [p["description"]["scale_ratio"] for p in pairs], "scale ratio (size in j / in i)", None
    return list(range(len(pairs))), "pair (view j)", [p["description"]["j"] for p in pairs]


def figure(runs: dict, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    cols = [(scene, name, kind) for scene, docs in runs.items() for name, kind, _ in series_of(docs[METHODS[0]])]
    fig, axes = plt.subplots(2, len(cols), figsize=(3.3 * len(cols), 6.4), squeeze=False)
    for c, (scene, name, kind) in enumerate(cols):
        top, bot = axes[0, c], axes[1, c]
        for m in METHODS:
            doc = runs[scene][m]
            s = doc["results"][f"series.{name}"]
            top.plot(s["thresholds_px"], s["mma"], "o-", ms=3, label=m.upper())
            pairs = next(p for n, _, p in series_of(doc) if n == name)
            x, xlabel, ticks = _x(kind, pairs)
            order = np.argsort(x, kind="stable")
            bot.plot(np.asarray(x)[order], np.asarray([p["mma"]["mma"][2] for p in pairs])[order], "o-", ms=4,
                     label=m.upper())
        top.set_title(f"{scene}: {name} ({kind}, {len(pairs)} pair{'s' if len(pairs) != 1 else ''})", fontsize=9)
        top.set_xlabel("threshold (px)")
        bot.set_xlabel(xlabel)
        if ticks is not None:
            bot.set_xticks(x)
            bot.set_xticklabels(ticks, rotation=45, ha="right", fontsize=7)
        if kind == "scale":  # log axis, ticks at the pairs' own ratios
            bot.set_xscale("log", base=2)
            bot.minorticks_off()
            bot.set_xticks(x, [f"{v:.3g}" for v in x])
        for ax in (top, bot):
            ax.set_ylim(0, 1.02)
            ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("MMA (mean over pairs)")
    axes[1, 0].set_ylabel("MMA@3 px (per pair)")
    axes[0, 0].legend(fontsize=8, loc="lower right")
    fig.suptitle("OpenCV detectors + descriptors, brute-force mutual nearest neighbours, default parameters "
                 "(exact truth, occlusion-aware)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    print(f"wrote {out}")


def table(runs: dict) -> str:
    lines = ["| scene | series | method | MMA@1 | MMA@3 | MMA@5 | repeatability | loc. err (px) | matching score |"
             " recall |", "|---|---|---|---|---|---|---|---|---|---|"]
    for scene, docs in runs.items():
        for m in METHODS:
            res = docs[m]["results"]
            for key in ["overall"] + [k for k in res if k.startswith("series.")]:
                s = res[key]
                mma = dict(zip(s["thresholds_px"], s["mma"]))
                loc = s["localisation_err_px"]
                lines.append(f"| {scene} | {s['series']} | {m} | {mma[1.0]:.3f} | {mma[3.0]:.3f} | {mma[5.0]:.3f} | "
                             f"{s['repeatability']:.3f} | {loc if isinstance(loc, str) else f'{loc:.2f}'} | "
                             f"{s['matching_score']:.3f} | {s['recall']:.3f} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT / "out" / "features_figure",
                    help="where the datasets and runs go (datasets already there are reused)")
    ap.add_argument("--scenes", type=Path, nargs="+", default=list(SCENES))
    ap.add_argument("--out", type=Path, default=OUT)
    a = ap.parse_args()
    runs = {}
    for spec in a.scenes:
        ds = render(spec, a.data)
        runs[spec.stem] = run_all(ds, a.data)
    figure(runs, a.out)
    print(table(runs))
    (a.data / "features_table.md").write_text(table(runs) + "\n")
    (a.data / "features_metrics.json").write_text(json.dumps({s: {m: d["metrics"] for m, d in docs.items()}
                                                              for s, docs in runs.items()}, indent=2) + "\n")


if __name__ == "__main__":
    main()
