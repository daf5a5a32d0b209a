"""``recon-eval cloud``: a point cloud or mesh against a truth cloud, mesh, or a dataset's scene
meshes (docs/metrics.md, "Point clouds and meshes")."""
from __future__ import annotations

import numpy as np

from recon_eval.cli.scored import scored
from recon_eval.metrics.distances import sample_mesh_surface
from recon_eval.metrics.pointcloud import chamfer, dtu, eth3d, tanks_and_temples, tanks_and_temples_distances
from recon_eval.readers.ply import read_geometry
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure


def arguments(p) -> None:
    p.add_argument("rec", help="reconstruction (.ply/.obj/.stl point cloud or mesh; its vertices are scored)")
    p.add_argument("gt", help="truth (.ply/.obj/.stl, or a dataset folder: its scene meshes); a mesh gives exact "
                              "point-to-triangle distances")
    p.add_argument("--tau", type=float, action="append", help="threshold(s) in metres (default 0.01)")
    p.add_argument("--gt-samples", type=int, default=200_000, help="surface samples of a GT mesh for recall/completeness")
    p.add_argument("--seed", type=int, default=0, help="seed of the GT mesh surface sample")
    p.add_argument("--no-downsample", action="store_true", help="skip Tanks and Temples' tau/2 voxel downsampling")
    p.add_argument("--eth3d-voxel", type=float, default=0.01, help="ETH3D per-voxel averaging size, metres")
    p.add_argument("--dtu-max-dist", type=float, default=0.02, help="DTU outlier cut, metres")


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
        mesh = (V, F)
        gt_pts = sample_mesh_surface(V, F, a.gt_samples, seed=a.seed)
    taus = a.tau or [0.01]
    res = {}
    for tau in taus:
        res[f"tanks_and_temples@{tau:g}m"] = tanks_and_temples(rec.vertices, gt_pts, tau, gt_mesh=mesh,
                                                              downsample=not a.no_downsample)
        res[f"eth3d@{tau:g}m"] = eth3d(rec.vertices, gt_pts, tau, gt_mesh=mesh, voxel_m=a.eth3d_voxel)
    res["dtu"] = dtu(rec.vertices, gt_pts, max_dist_m=a.dtu_max_dist, gt_mesh=mesh)
    res["chamfer"] = chamfer(rec.vertices, gt_pts, gt_mesh=mesh)
    inputs = {"rec": a.rec, "gt": a.gt, "gt_kind": gt_kind, "gt_is_mesh": mesh is not None,
              "gt_points": "mesh surface sample" if mesh is not None else "file vertices",
              "gt_samples": a.gt_samples if mesh is not None else None, "seed": a.seed, "tau_m": taus}

    def figures():
        tau = taus[0]
        d_rg, d_gr, _, _ = tanks_and_temples_distances(rec.vertices, gt_pts, tau, gt_mesh=mesh,
                                                       downsample=not a.no_downsample)
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


COMMANDS = {"cloud": scored(arguments, score)}
