"""``recon-eval cloud``: a point cloud or mesh against a truth cloud, mesh, or a dataset's scene
meshes (docs/metrics.md, "Point clouds and meshes")."""
from __future__ import annotations

import numpy as np

from recon_eval.cli.common import stderr_progress
from recon_eval.cli.scored import scored
from recon_eval.metrics.distances import MeshSurface, sample_mesh_surface
from recon_eval.metrics.pointcloud import (ETH3D_TOLERANCES_M, chamfer, dtu, eth3d_table, tanks_and_temples,
                                          tanks_and_temples_distances)
from recon_eval.metrics.surfaces import mesh_comparison
from recon_eval.metrics.tnt import crop_mask, tanks_and_temples_curves
from recon_eval.readers.crop_volume import read_crop_volume
from recon_eval.readers.ply import read_geometry
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure
from recon_eval.tasks.headlines import CLOUD_TAU_M, cloud_headline


def arguments(p) -> None:
    p.add_argument("rec", help="reconstruction (.ply/.obj/.stl point cloud or mesh; its vertices are scored)")
    p.add_argument("gt", help="truth (.ply/.obj/.stl, or a dataset folder: its scene meshes); a mesh gives exact "
                              "point-to-triangle distances")
    p.add_argument("--tau", type=float, action="append", help="Tanks and Temples threshold(s) in metres (default 0.01)")
    p.add_argument("--eth3d-tolerance", type=float, action="append",
                   help="ETH3D tolerance(s) in metres (default ETH3D's table 0.01 0.02 0.05 0.1 0.2 0.5; each --tau "
                        "is evaluated too)")
    p.add_argument("--gt-samples", type=int, default=200_000, help="surface samples of a GT mesh for recall/completeness")
    p.add_argument("--seed", type=int, default=0, help="seed of the GT mesh surface sample")
    p.add_argument("--no-downsample", action="store_true", help="skip Tanks and Temples' tau/2 voxel downsampling")
    p.add_argument("--eth3d-voxel", type=float, default=0.01, help="ETH3D per-voxel averaging size, metres")
    p.add_argument("--dtu-max-dist", type=float, default=0.02, help="DTU outlier cut, metres")
    p.add_argument("--crop", metavar="JSON", help="Tanks and Temples crop volume (an Open3D SelectionPolygonVolume "
                                                  "JSON): both clouds are cropped before scoring")
    p.add_argument("--mesh-samples", type=int, default=100_000,
                   help="mesh against mesh: Occupancy Networks' surface samples per mesh and IoU points")


def score(a):
    rec = read_geometry(a.rec)
    gt_kind = "file"
    if is_dataset(a.gt):
        V, F = read_dataset(a.gt).mesh()
        gt_kind = "scenegen-dataset scene/meshes"
    else:
        g = read_geometry(a.gt)
        V, F = g.vertices, g.faces
    mesh = None
    gt_pts = V
    if F is not None and len(F):
        mesh = MeshSurface(V, F, progress=stderr_progress("distances to the GT mesh"))
        gt_pts = sample_mesh_surface(V, F, a.gt_samples, seed=a.seed)
    rec_pts = rec.vertices
    crop = None
    if a.crop:
        crop = read_crop_volume(a.crop)
        rec_pts, gt_pts = rec_pts[crop_mask(rec_pts, crop)], gt_pts[crop_mask(gt_pts, crop)]
    taus = a.tau or [0.01]
    tols = tuple(sorted(set(a.eth3d_tolerance or ETH3D_TOLERANCES_M) | set(taus)))
    res = {}
    for tau in taus:
        res[f"tanks_and_temples@{tau:g}m"] = tanks_and_temples(rec_pts, gt_pts, tau, gt_mesh=mesh,
                                                              downsample=not a.no_downsample)
    for r in eth3d_table(rec_pts, gt_pts, tols, gt_mesh=mesh, voxel_m=a.eth3d_voxel):
        res[f"eth3d@{r.tolerance_m:g}m"] = r
    res["dtu"] = dtu(rec_pts, gt_pts, max_dist_m=a.dtu_max_dist, gt_mesh=mesh)
    res["chamfer"] = chamfer(rec_pts, gt_pts, gt_mesh=mesh)
    curves = {}
    for tau in taus:
        d_rg, d_gr, _, _ = tanks_and_temples_distances(rec_pts, gt_pts, tau, gt_mesh=mesh,
                                                       downsample=not a.no_downsample)
        curves[tau] = (d_rg, d_gr)
        res[f"tanks_and_temples_curves@{tau:g}m"] = tanks_and_temples_curves(d_rg, d_gr, tau)
    if mesh is not None and rec.faces is not None and len(rec.faces):
        res["occupancy_networks"] = mesh_comparison(rec.vertices, rec.faces, V, F, n_samples=a.mesh_samples,
                                                    n_iou_points=a.mesh_samples, seed=a.seed)
    inputs = {"rec": a.rec, "gt": a.gt, "gt_kind": gt_kind, "gt_is_mesh": mesh is not None,
              "gt_points": "mesh surface sample" if mesh is not None else "file vertices",
              "gt_samples": a.gt_samples if mesh is not None else None, "seed": a.seed, "tau_m": taus,
              "eth3d_tolerances_m": list(tols), "crop": a.crop,
              "n_rec_cropped": None if crop is None else len(rec_pts), "n_gt_cropped": None if crop is None else len(gt_pts)}

    def figures():
        tau = taus[0]
        d_rg, d_gr = curves[tau]
        ts = np.linspace(0.0, 5.0 * max(taus), 201)[1:]
        return [
            Figure("Precision / recall / F-score vs tau",
                   plots.precision_recall_figure(d_rg, d_gr, ts, tau_m=tau, title="Tanks and Temples, strict <"),
                   f"distances after voxel downsampling at {tau:g}/2 m, as the Tanks and Temples toolbox plots them"),
            Figure("Cumulative distances",
                   plots.cumulative_figure({"rec -> GT (precision side)": d_rg, "GT -> rec (recall side)": d_gr},
                                           xlabel="distance (m)", title="cumulative distance distribution",
                                           thresholds=taus, xmax=5.0 * max(taus))),
        ]

    return inputs, res, figures


def metrics(a, res) -> dict:
    """``metrics`` of ``cloud --json``: the names a cloud run gives the same numbers (Tanks and
    Temples at 1 cm, Chamfer-L1), present when --tau includes 0.01 m and nothing is cropped."""
    return cloud_headline(res) if f"tanks_and_temples@{CLOUD_TAU_M:g}m" in res and not a.crop else {}


COMMANDS = {"cloud": scored(arguments, score, metrics)}
