"""Tanks and Temples F-score, 1M vs 1M points: recon_eval vs an Open3D implementation.

The Open3D side is the Tanks and Temples toolbox's computation (isl-org/TanksAndTemples,
python_toolbox/evaluation): ``voxel_down_sample(tau / 2)`` of both clouds,
``compute_point_cloud_distance`` both ways, precision = mean(d(rec->gt) < tau), recall =
mean(d(gt->rec) < tau) (strict <), F = 2PR / (P + R). recon_eval's side is
:func:`recon_eval.metrics.pointcloud.tanks_and_temples` on the same clouds. Both are timed warm (one
untimed run first, then the best of ``--repeats``), from numpy arrays in memory to P/R/F.

Open3D is never installed in the project's environment: on first use this script creates a
separate venv (``benchmarks/.venv-open3d``, ignored by git) with ``open3d==0.20.0`` and re-executes
its Open3D half there, on the clouds saved to temporary .npy files. Open3D's wheel links
``libusb-1.0.so.0``; on Debian/Ubuntu ``apt-get install libusb-1.0-0`` provides it.

Usage::

    .venv/bin/python benchmarks/bench_fscore.py [--n 1000000] [--tau 0.01] [--repeats 3]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
VENV = HERE / ".venv-open3d"
OPEN3D_REQ = "open3d==0.20.0"


# --- the Open3D half (runs inside the benchmark venv) -----------------------------------------
def open3d_worker(rec_path: str, gt_path: str, tau: float, repeats: int) -> None:
    import numpy as np
    import open3d as o3d

    rec_np, gt_np = np.load(rec_path), np.load(gt_path)

    def tanks_and_temples_open3d():
        rec = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(rec_np))
        gt = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(gt_np))
        rec = rec.voxel_down_sample(tau / 2.0)
        gt = gt.voxel_down_sample(tau / 2.0)
        d_rg = np.asarray(rec.compute_point_cloud_distance(gt))
        d_gr = np.asarray(gt.compute_point_cloud_distance(rec))
        p = float(np.mean(d_rg < tau))
        r = float(np.mean(d_gr < tau))
        f = 0.0 if p + r == 0 else 2 * p * r / (p + r)
        return p, r, f, len(d_rg), len(d_gr)

    tanks_and_temples_open3d()  # warm-up
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = tanks_and_temples_open3d()
        times.append(time.perf_counter() - t0)
    print(json.dumps({"times_s": times, "precision": out[0], "recall": out[1], "fscore": out[2],
                      "n_rec": out[3], "n_gt": out[4], "open3d": o3d.__version__}))


# --- the main half (project venv) -------------------------------------------------------------
def ensure_open3d_venv() -> Path:
    py = VENV / "bin" / "python"
    ok = py.is_file() and subprocess.run([str(py), "-c", "import open3d"], capture_output=True).returncode == 0
    if not ok:
        if not py.is_file():
            print(f"creating {VENV} (separate venv for Open3D; never the project's)", flush=True)
            subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
        print(f"installing {OPEN3D_REQ} into {VENV} ...", flush=True)
        subprocess.run([str(py), "-m", "pip", "install", "-q", OPEN3D_REQ], check=True)
        res = subprocess.run([str(py), "-c", "import open3d"], capture_output=True, text=True)
        if res.returncode != 0:
            hint = " (install the system library: apt-get install libusb-1.0-0)" if "libusb" in res.stderr else ""
            sys.exit(f"open3d does not import in {VENV}{hint}:\n{res.stderr.strip().splitlines()[-1]}")
    return py


def make_clouds(n: int, tau: float, seed: int = 0):
    """GT: n points uniformly on a unit sphere (surface area 12.6 m^2). Reconstruction: n other
    points on the same sphere, displaced along the normal by N(0, tau/2), plus 5 % outliers
    uniform in the [-1.2, 1.2]^3 box. Metres."""
    import numpy as np

    rng = np.random.default_rng(seed)

    def sphere(m):
        v = rng.normal(size=(m, 3))
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    gt = sphere(n)
    n_out = n // 20
    s = sphere(n - n_out)
    rec = np.concatenate([s * (1.0 + rng.normal(0.0, tau / 2.0, (n - n_out, 1))), rng.uniform(-1.2, 1.2, (n_out, 3))])
    return rec[rng.permutation(n)], gt


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000, help="points per cloud")
    ap.add_argument("--tau", type=float, default=0.01, help="threshold, metres")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs after one warm-up (best is reported)")
    ap.add_argument("--open3d-worker", nargs=2, metavar=("REC_NPY", "GT_NPY"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.open3d_worker:
        open3d_worker(*a.open3d_worker, a.tau, a.repeats)
        return 0

    import numpy as np

    sys.path.insert(0, str(HERE.parent))
    from recon_eval.metrics.pointcloud import tanks_and_temples

    py = ensure_open3d_venv()
    rec, gt = make_clouds(a.n, a.tau)
    with tempfile.TemporaryDirectory() as tmp:
        np.save(Path(tmp) / "rec.npy", rec)
        np.save(Path(tmp) / "gt.npy", gt)
        res = subprocess.run([str(py), __file__, "--open3d-worker", str(Path(tmp) / "rec.npy"), str(Path(tmp) / "gt.npy"),
                              "--tau", repr(a.tau), "--repeats", str(a.repeats)],
                             capture_output=True, text=True, env={**os.environ, "PYTHONPATH": ""})
        if res.returncode != 0:
            sys.exit(f"Open3D worker failed:\n{res.stderr}")
        o3d = json.loads(res.stdout.strip().splitlines()[-1])

    tanks_and_temples(rec, gt, a.tau)  # warm-up
    times = []
    for _ in range(a.repeats):
        t0 = time.perf_counter()
        ours = tanks_and_temples(rec, gt, a.tau)
        times.append(time.perf_counter() - t0)

    t_ours, t_o3d = min(times), min(o3d["times_s"])
    print(f"Tanks and Temples F-score, {a.n:,} vs {a.n:,} points, tau = {a.tau} m, {os.cpu_count()} CPU cores,"
          f" best of {a.repeats} warm runs")
    print(f"  after voxel_down_sample(tau/2): rec {ours.n_rec:,} / gt {ours.n_gt:,} points"
          f" (Open3D: {o3d['n_rec']:,} / {o3d['n_gt']:,})")
    print(f"  recon_eval    : {t_ours:7.3f} s   P={ours.precision:.6f} R={ours.recall:.6f} F={ours.fscore:.6f}")
    print(f"  Open3D {o3d['open3d']:7s}: {t_o3d:7.3f} s   P={o3d['precision']:.6f} R={o3d['recall']:.6f}"
          f" F={o3d['fscore']:.6f}")
    ratio = t_ours / t_o3d
    print(f"  time ratio recon_eval / Open3D = {ratio:.2f} ({'not slower' if ratio <= 1.0 else 'SLOWER'})")
    dp, dr, df = (abs(ours.precision - o3d["precision"]), abs(ours.recall - o3d["recall"]),
                  abs(ours.fscore - o3d["fscore"]))
    # a point whose distance sits within float rounding of tau may flip: allow one point each way
    agree = (ours.n_rec, ours.n_gt) == (o3d["n_rec"], o3d["n_gt"]) and dp <= 1.0 / ours.n_rec and dr <= 1.0 / ours.n_gt
    print(f"  |dP| = {dp:.2e}, |dR| = {dr:.2e}, |dF| = {df:.2e}: {'agree' if agree else 'DISAGREE'}")
    return 0 if agree else 1


if __name__ == "__main__":
    sys.exit(main())
