"""A small synthetic BOP dataset written in the official layout, for the object runners' tests:
a textured table plane and three objects (a box with a declared 180-degree symmetry, an
asymmetric wedge, a second box instance) in two test images, and a ``train/`` split of each
model alone from 12 viewpoints (the reference renders). Texture: a seeded sum of sines of the
model-frame point, so SIFT finds the same features in the reference renders and the test images.
Depth and colour come from recon_eval's ray-cast renderer (exact, no noise)."""
from __future__ import annotations

import json

import cv2
import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from recon_eval.metrics.objects_depth import model_points, render_depth

W, H = 320, 240
K = np.array([[440.0, 0.0, 159.5], [0.0, 440.0, 119.5], [0.0, 0.0, 1.0]])
#: the box's half-turns about z, y and x: its shape's symmetries (BOP declares what the shape cannot tell
#: apart; the texture could, but a depth-only method cannot see it)
FLIPS = [[-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1], [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1],
         [1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1]]


def meshes():
    wedge = trimesh.convex.convex_hull(np.array([[-40, -25, -15], [45, -25, -15], [-40, 30, -15], [-40, -25, 35.0],
                                                 [0, 0, 20.0]]))
    return {1: trimesh.creation.box(extents=(70.0, 40.0, 30.0)), 2: wedge}


def _texture(points, seed):
    rng = np.random.default_rng(seed)
    freqs = rng.normal(0, 1 / 4.0, (24, 3))
    phases = rng.uniform(0, 2 * np.pi, 24)
    val = np.sin(points @ freqs.T + phases).sum(axis=-1)
    return np.clip(128 + 20 * val, 0, 255)


def _table(R_table):
    return trimesh.creation.box(extents=(900.0, 900.0, 2.0)), R_table, np.array([0.0, 40.0, 640.0])


def _render(items):
    """items: (mesh, R, t, texture seed) -> (grey uint8 image, depth mm)."""
    depth = np.zeros((H, W))
    grey = np.zeros((H, W))
    for mesh, R, t, seed in items:
        d = render_depth(mesh.vertices, mesh.faces, R, t, K, W, H)
        closer = (d > 0) & ((depth == 0) | (d < depth))
        pts = model_points(d, R, t, K)
        depth = np.where(closer, d, depth)
        grey = np.where(closer, _texture(np.nan_to_num(pts), seed), grey)
    return grey.astype(np.uint8), depth


def poses():
    rot = lambda *deg: Rotation.from_euler("xyz", deg, degrees=True).as_matrix()  # noqa: E731
    return {0: [(1, rot(-40, 10, 30), np.array([-45.0, -5.0, 480.0])), (2, rot(-30, 20, -40), np.array([60.0, 5.0, 500.0])),
                (1, rot(-50, -10, 120), np.array([0.0, 45.0, 560.0]))],
            1: [(1, rot(-30, 0, -20), np.array([40.0, -10.0, 470.0])), (2, rot(-45, -15, 60), np.array([-50.0, 20.0, 520.0]))]}


def write(root, scale_mm=0.1):
    ms = meshes()
    (root / "models").mkdir(parents=True)
    info = {}
    for oid, m in ms.items():
        m.export(root / "models" / f"obj_{oid:06d}.ply")
        v = np.asarray(m.vertices)
        info[str(oid)] = {"diameter": float(np.max(np.linalg.norm(v[:, None] - v[None], axis=2)))}
    info["1"]["symmetries_discrete"] = FLIPS
    (root / "models" / "models_info.json").write_text(json.dumps(info))
    (root / "camera.json").write_text(json.dumps({"width": W, "height": H, "fx": K[0, 0], "fy": K[1, 1],
                                                  "cx": K[0, 2], "cy": K[1, 2], "depth_scale": scale_mm}))
    table = _table(Rotation.from_euler("x", -35, degrees=True).as_matrix())
    _split(root / "test" / "000000", {im: [(ms[o], R, t, o, o) for o, R, t in p] + [(table[0], table[1], table[2], 99, None)]
                                      for im, p in poses().items()}, scale_mm)
    ref = {}
    for oid in ms:  # reference renders: each model alone, 16 viewpoints around it
        for k in range(16):
            R = Rotation.from_euler("xyz", [-60 + 30 * (k // 8), 0, 45 * k], degrees=True).as_matrix()
            ref[len(ref)] = [(ms[oid], R, np.array([0.0, 0.0, 450.0]), oid, oid)]
    _split(root / "train" / "000000", ref, scale_mm)
    targets = [{"scene_id": 0, "im_id": im, "obj_id": o, "inst_count": n} for im, p in poses().items()
               for o, n in sorted({o: sum(1 for q, _, _ in p if q == o) for o, _, _ in p}.items())]
    (root / "test_targets_bop19.json").write_text(json.dumps(targets))
    return root


def _split(sdir, images, scale_mm):
    for sub in ("rgb", "depth"):
        (sdir / sub).mkdir(parents=True)
    gt, gt_info, cam = {}, {}, {}
    for im, items in images.items():
        grey, depth = _render([(m, R, t, seed) for m, R, t, seed, _ in items])
        cv2.imwrite(str(sdir / "rgb" / f"{im:06d}.png"), np.dstack([grey] * 3))
        cv2.imwrite(str(sdir / "depth" / f"{im:06d}.png"), np.round(depth / scale_mm).astype(np.uint16))
        objs = [(m, R, t, o) for m, R, t, _, o in items if o is not None]
        gt[str(im)] = [{"obj_id": o, "cam_R_m2c": R.ravel().tolist(), "cam_t_m2c": t.tolist()} for _, R, t, o in objs]
        fr = []
        for m, R, t, _ in objs:
            alone = render_depth(m.vertices, m.faces, R, t, K, W, H)
            fr.append({"visib_fract": float(((alone > 0) & (np.abs(alone - depth) < 1e-6)).sum() / max((alone > 0).sum(), 1))})
        gt_info[str(im)] = fr
        cam[str(im)] = {"cam_K": K.ravel().tolist(), "depth_scale": scale_mm}
    for name, doc in (("scene_gt", gt), ("scene_gt_info", gt_info), ("scene_camera", cam)):
        (sdir / f"{name}.json").write_text(json.dumps(doc))
