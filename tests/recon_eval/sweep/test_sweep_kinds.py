"""recon-eval sweep for H, E, PnP and triangulation (issue 34: "the same sweep serves H, E, PnP and
triangulation runners"): their truth against the dataset's own, exact noise-free cells, error
growing with noise, robust methods holding where the others break down, bitwise reproducibility,
and the CLI on the analytic plane dataset."""
from __future__ import annotations

import json

import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.errors import InputError
from recon_eval.metrics.dlt import project_with_P
from recon_eval.metrics.triangulation import projection_matrix
from recon_eval.readers.scenegen_dataset import read_dataset
from recon_eval.runners.common import RunOutput
from recon_eval.sweep.draw import draw_view_trial
from recon_eval.sweep.kinds import KINDS
from recon_eval.sweep.run import SweepConfig, run_sweep
from recon_eval.sweep.truth import ViewsTruth, plane_of
from scenegen.geometry.pose import look_at
from scenegen.geometry.twoview import apply_homography

K = np.array([[400.0, 0.0, 239.5], [0.0, 400.0, 179.5], [0.0, 0.0, 1.0]])
SIZE = (480, 360)


def closed_form(views: int, n: int = 2000, seed: int = 11) -> ViewsTruth:
    """Points in a 1.6 x 1.2 x 1.0 m box seen by wide_baseline.yaml's cameras (as the F sweep's
    fixture), pixels projected in float64: a non-planar scene, exact to rounding."""
    rng = np.random.default_rng(seed)
    X = rng.uniform([-0.8, -0.6, -0.5], [0.8, 0.6, 0.5], (n, 3)) + [0.0, 0.3, 0.5]
    poses = (look_at((-0.75, -1.45, 0.9), (0.0, 0.3, 0.5)).inverse(),
             look_at((0.75, -1.45, 0.9), (0.0, 0.3, 0.5)).inverse())[:views]
    P = tuple(projection_matrix(K, p.R, p.t) for p in poses)
    return ViewsTruth(("v1", "v2")[:views], X, tuple(project_with_P(p, X) for p in P), (K,) * views, poses, P,
                      (SIZE,) * views, {})


@pytest.fixture(scope="module")
def truths(plane_dataset):
    """The kinds' truths: H on the plane dataset's stereo pair (a planar scene), the others closed form."""
    ds = read_dataset(plane_dataset[0])
    return {"h": KINDS["h"].truth(ds, ("left_000", "right_000"), 20000), "e": closed_form(2),
            "pnp": closed_form(1), "triangulation": closed_form(2)}


def sweep(kind, truth, cfg, tmp, methods=None):
    k = KINDS[kind]
    ms = k.resolve(methods or k.default_methods(), {}, RunOutput())
    res = run_sweep(truth, ms, SweepConfig(*cfg, kind=kind), tmp)
    return res, {(c["method"], c["sigma_px"], c["outlier_fraction"]): c for c in res["cells"]}


def test_h_truth_maps_the_datasets_own_correspondences(plane_dataset, truths):
    """The truth H (plane fit + closed form) against the dataset's stored correspondence truth
    (crossview/corr, float32): agree within 2e-5 px; a non-planar scene is refused."""
    ds = read_dataset(plane_dataset[0])
    x1, x2 = ds.correspondences("left_000", "right_000")
    H = np.asarray(truths["h"].notes["H_gt"])
    assert len(x1) > 500 and np.max(np.linalg.norm(apply_homography(H, x1) - x2, axis=1)) < 2e-5
    with pytest.raises(InputError, match="not coplanar"):
        plane_of(closed_form(1).X, 1e-5)


def test_view_truth_pixels_are_the_datasets_pixel_centres(plane_dataset):
    """PnP's truth pixels (float64 projections of the stored points) land on the pixel centres the
    points were stored for, within float32 rounding of the points (1e-4 px at 40 px focal)."""
    ds = read_dataset(plane_dataset[0])
    t = KINDS["pnp"].truth(ds, ("left_000",), 20000)
    uv, _ = ds.points_at_pixels("left_000", max_points=20000, seed=0)
    assert len(uv) == 1200 and np.max(np.abs(t.x[0] - uv)) < 1e-4


def test_view_trial_has_the_stated_noise_and_outliers():
    t = closed_form(1)
    a = draw_view_trial(t.x[0], SIZE, 1500, 2.0, 0.2, 7, (1, 2), 3, "pnp-sweep")
    b = draw_view_trial(t.x[0], SIZE, 1500, 2.0, 0.2, 7, (1, 2), 3, "pnp-sweep")
    assert all(np.array_equal(getattr(a, f), getattr(b, f)) for f in ("x", "t", "rows", "inliers"))
    assert (~a.inliers).sum() == 300 and np.array_equal(a.t, t.x[0][a.rows])
    e = (a.x - a.t)[a.inliers].ravel()
    assert abs(np.std(e) - 2.0) < 5 * 2.0 / np.sqrt(2 * len(e))
    with pytest.raises(InputError, match="fewer than --points"):
        draw_view_trial(t.x[0][:10], SIZE, 20, 0.0, 0.0, 0, (0, 0), 0, "pnp-sweep")


#: Noise-free floors per kind (the kind's unit), and per method where a method's own arithmetic
#: sets it; measured maxima over 5 trials of 100 points in the comments. E, PnP and triangulation
#: have float64 closed-form truth, H the dataset's float32 truth points.
FLOORS = {"h": 1e-6,  # least squares, RANSAC, LMedS: 2.7e-7 px
          "e": 1e-9,  # RANSAC, LMedS: 6.4e-13 deg
          "pnp": 1e-9,  # solvePnP: 1.3e-12 px
          "triangulation": 1e-12}  # 3.5e-16 m
METHOD_FLOORS = {"opencv-h-rho": 1e-5,  # 1.6e-6 px
                 "opencv-h-usac-magsac": 1e-4,  # 1.6e-5 px: MAGSAC's sigma-weighted final fit
                 "opencv-e-usac-magsac": 1e-3,  # 4.8e-5 deg
                 # solvePnPRansac works on float32 copies of the points: 3.1e-6 px
                 **{f"opencv-pnp-ransac-{s}": 1e-5 for s in ("iterative", "epnp", "sqpnp")}}


@pytest.mark.parametrize("kind", ["h", "e", "pnp", "triangulation"])
def test_noise_free_cells_are_exact_and_error_grows_with_noise(kind, truths, tmp_path):
    _, cells = sweep(kind, truths[kind], ((0.0, 0.5, 3.0), (0.0,), 5, 100, 1, KINDS[kind].default_breakdown),
                     tmp_path)
    mean = KINDS[kind].cell_keys[0]
    for m in KINDS[kind].default_methods():
        c0, c1, c2 = (cells[(m, s, 0.0)] for s in (0.0, 0.5, 3.0))
        assert c0["n_failed"] == 0 and c0[mean] < METHOD_FLOORS.get(m, FLOORS[kind]), (m, c0[mean])
        assert c0[mean] < c1[mean] < c2[mean], (m, c0[mean], c1[mean], c2[mean])


#: (kind, a method that holds at 30 % outliers, one that breaks down there)
ROBUST = [("h", "opencv-h-ransac", "opencv-h-ls"), ("e", "opencv-e-ransac", None),
          ("pnp", "opencv-pnp-ransac-epnp", "opencv-pnp-epnp")]


@pytest.mark.parametrize("kind,robust,breaks", ROBUST)
def test_robust_methods_hold_where_least_squares_breaks_down(kind, robust, breaks, truths, tmp_path):
    k = KINDS[kind]
    methods = [robust] + ([breaks] if breaks else [])
    res, cells = sweep(kind, truths[kind], ((0.5,), (0.0, 0.3), 3, 100, 2, k.default_breakdown), tmp_path, methods)
    rows = {r["method"]: r for r in res["breakdown"]}
    assert rows[robust]["breakdown_fraction"] is None and cells[(robust, 0.5, 0.3)]["success_rate"] == 1.0
    if breaks:
        assert rows[breaks]["breakdown_fraction"] == 0.3


def test_triangulation_outliers_spoil_only_their_own_points(truths, tmp_path):
    """Per-point triangulation has no consensus to break: with 30 % outliers the inliers' mean error
    is what noise alone gives (within the spread of 4 trials' means: measured ratio 0.95-1.07)."""
    res, cells = sweep("triangulation", truths["triangulation"], ((1.0,), (0.0, 0.3), 4, 200, 3, 0.05), tmp_path)
    assert all(r["breakdown_fraction"] is None for r in res["breakdown"])
    for m in KINDS["triangulation"].default_methods():
        clean, spoilt = cells[(m, 1.0, 0.0)]["mean_err_m"], cells[(m, 1.0, 0.3)]["mean_err_m"]
        assert 0 < clean < 0.05 and 0.8 < spoilt / clean < 1.25


@pytest.mark.parametrize("kind", ["h", "e", "pnp", "triangulation"])
def test_sweep_is_bitwise_reproducible(kind, truths, tmp_path):
    cfg = ((1.0,), (0.0, 0.3), 2, 60, 3, KINDS[kind].default_breakdown)
    docs = [json.dumps(sweep(kind, truths[kind], cfg, tmp_path / str(i))[0], allow_nan=True).encode() for i in (0, 1)]
    assert docs[0] == docs[1]
    other = ((1.0,), (0.0, 0.3), 2, 60, 4, KINDS[kind].default_breakdown)
    assert json.dumps(sweep(kind, truths[kind], other, tmp_path / "2")[0], allow_nan=True).encode() != docs[0]


def _cli(dataset, out, kind, *extra) -> int:
    """``recon-eval sweep`` in this process (its exit code; stderr through capsys)."""
    return main(["sweep", str(dataset), "-o", str(out), "--kind", kind, "--sigmas", "1", "--outliers", "0", "0.2",
                 "--trials", "2", "--points", "60", "--quiet", *extra])


@pytest.mark.parametrize("kind,views", [("h", ["left_000", "free_000"]), ("e", ["left_000", "free_000"]),
                                        ("pnp", ["free_000"]), ("triangulation", ["left_000", "right_000"])])
def test_cli_sweep_each_kind(kind, views, plane_dataset, tmp_path, capsys):
    """On the analytic plane dataset (free_000: an OpenCV camera with distortion, swept in its
    undistorted pixels); the tables and the report follow the kind's error."""
    extra = ["--object", "plane"] if kind == "h" else []  # (every point is on it)
    code = _cli(plane_dataset[0], tmp_path / "o", kind, "--views", *views, "--markdown", str(tmp_path / "t.md"), *extra)
    assert code == 0, capsys.readouterr().err
    doc = json.loads((tmp_path / "o" / "sweep.json").read_bytes())
    k = KINDS[kind]
    assert doc["inputs"]["kind"] == kind and doc["inputs"]["views"] == views
    assert doc["inputs"]["truth"]["points"].endswith("on object 'plane'") == (kind == "h")
    assert doc["results"]["error"]["unit"] == k.unit and doc["results"]["config"]["breakdown"] == k.default_breakdown
    assert {c["method"] for c in doc["results"]["cells"]} == set(k.default_methods())
    assert len(doc["results"]["cells"]) == 2 * len(k.default_methods())
    page = (tmp_path / "o" / "report.html").read_text()
    assert page.count("data:image/png;base64,") == 2 and k.unit in (tmp_path / "t.md").read_text()


def test_cli_sweep_kind_bad_input_exits_2(plane_dataset, tmp_path, capsys):
    root = plane_dataset[0]
    for args, msg in [(("pnp", "--views", "left_000", "right_000"), "takes 1 view"),
                      (("h", "--views", "left_000", "right_000", "--command", "{python} x.py {matches} {out}"),
                       "F methods only"),
                      (("e", "--views", "left_000", "right_000", "--methods", "opencv-f-8point"),
                       "unknown method 'opencv-f-8point'"),
                      (("triangulation", "--views", "left_000", "left_000"), "must differ"),
                      (("h", "--views", "left_000", "right_000", "--object", "wall"), "spec.objects"),
                      (("f", "--views", "left_000", "right_000", "--object", "plane"), "not for --kind f")]:
        code = _cli(root, tmp_path / "o", *args)
        err = capsys.readouterr().err
        assert code == 2 and msg in err and err.count("\n") == 1, (args, err)
