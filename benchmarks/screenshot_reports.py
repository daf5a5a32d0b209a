"""Screenshots of each recon-eval report kind, taken with a real headless browser (not a test):
the leaderboard page, a run's report.html, and the --html reports of two scoring commands
(fmatrix, disparity). They go to docs/figures/report_*.png (docs/ci.md, "Reports").

It renders scenes/wide_baseline.yaml and scenes/stereo_tabletop.yaml at their own settings, runs
a leaderboard of examples/methods.yaml's estimators beside OpenCV's (gated by
examples/gates_my_fmatrix.yaml), scores the my-fmatrix F with ``recon-eval fmatrix --html`` and
the SGBM disparity with ``recon-eval disparity --html``, then opens each page in headless Chromium
(``apt-get install -y chromium``; or set CHROMIUM=/path/to/chrome) and saves a PNG.

Run from the repository root: .venv/bin/python benchmarks/screenshot_reports.py [--work DIR]
(about a minute on 2 cores). ``--skip-render`` reuses the datasets in --work.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT  # noqa: E402

FIGURES = ROOT / "docs" / "figures"
#: (output PNG, page relative to the work folder, window width, height)
SHOTS = (("report_leaderboard.png", "board/leaderboard.html#sort=synthetic.sampson_rms_px", 1400, 860),
         ("report_run.png", "board/wide_baseline/my-fmatrix-transposed/report.html", 1200, 760),
         ("report_fmatrix.png", "fmatrix.html", 1200, 1500),
         ("report_disparity.png", "disparity.html", 1200, 1300))


def _browser() -> str:
    for cand in (os.environ.get("CHROMIUM"), "chromium", "chromium-browser", "google-chrome"):
        if cand and shutil.which(cand):
            return shutil.which(cand)
    raise SystemExit("no headless browser: apt-get install -y chromium (or set CHROMIUM=/path/to/chrome)")


def _sh(*args, ok=(0,)) -> None:
    print("$", " ".join(map(str, args)), file=sys.stderr, flush=True)
    r = subprocess.run([str(a) for a in args], cwd=ROOT, check=False)
    if r.returncode not in ok:
        raise SystemExit(f"exit status {r.returncode}: {' '.join(map(str, args))}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", default="/tmp/recon_eval_screens", help="work folder (datasets, runs, pages)")
    ap.add_argument("--skip-render", action="store_true", help="reuse the datasets already in --work")
    a = ap.parse_args()
    work = Path(a.work).resolve()
    py = sys.executable
    scenegen, recon = (py, "-m", "scenegen.cli"), (py, "-m", "recon_eval")
    if not a.skip_render:
        for scene in ("wide_baseline", "stereo_tabletop"):
            _sh(*scenegen, "render", f"scenes/{scene}.yaml", "-o", work / scene, "-q")
    board = work / "board"
    _sh(*recon, "leaderboard", "--methods-file", "examples/methods.yaml", "--datasets", work / "wide_baseline",
        work / "stereo_tabletop", "--methods", "my-fmatrix", "my-fmatrix-transposed", "my-f-matches",
        "opencv-f-ransac", "opencv-f-8point", "opencv-stereo-bm", "opencv-stereo-sgbm",
        "--gates", "examples/gates_my_fmatrix.yaml", "-o", board, ok=(0, 1))  # the transposed F fails its gates
    _sh(*recon, "fmatrix", board / "wide_baseline/my-fmatrix/pair_0000__pair_0001/F.txt", "--dataset",
        work / "wide_baseline", "--views", "pair_0000", "pair_0001", "--method", "my-fmatrix", "--quiet",
        "--html", work / "fmatrix.html")
    _sh(*recon, "disparity", board / "stereo_tabletop/opencv-stereo-sgbm/disparity/stereo_left_0000.pfm",
        work / "stereo_tabletop", "--view", "stereo_left_0000", "--benchmark", "middlebury",
        "--method", "opencv-stereo-sgbm", "--quiet", "--html", work / "disparity.html")
    browser = _browser()
    FIGURES.mkdir(parents=True, exist_ok=True)
    for png, page, w, h in SHOTS:
        _sh(browser, "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
            "--force-device-scale-factor=1", f"--window-size={w},{h}", f"--screenshot={FIGURES / png}",
            f"file://{work / page}")
        print(f"wrote {FIGURES / png}")


if __name__ == "__main__":
    main()
