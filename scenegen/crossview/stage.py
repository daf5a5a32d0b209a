"""The cross-view stage of the pipeline: runs after every view is rendered, writes
``crossview/...`` through the dataset writer (atomic, hashed in the manifest).

Only views that are complete in the dataset take part (a ``--frames`` run covers the pairs it
has). Each view's truth points are recomputed in float64 by the truth pass (one ray cast per
pixel, milliseconds; the same call as the stored truth), so resumed runs give the same bytes.
Views are projected into each other with their mid-exposure poses (the scene is at
mid-exposure, as for the truth): for a moving camera with a rolling shutter, i's points follow
its per-row poses but j is projected as a global shutter at its mid-exposure pose. Rectified
stereo views are ideal pinholes: no lens blur, motion or chromatic aberration, and the
pipeline's clean sRGB encoding, both under the left view's lighting (its view set's
``lights``). File layout: docs/crossview.md.
"""
from __future__ import annotations

import hashlib
import itertools
from dataclasses import dataclass
from typing import Callable

import numpy as np

from scenegen import io as sio
from scenegen.crossview import correspondence as cc
from scenegen.crossview import disparity as dsp
from scenegen.crossview.flow import encode_flo
from scenegen.crossview.matches import MATCH_COLUMNS, LABELS, MatchParams, label_real_matches, sift_matches, synthetic_matches
from scenegen.crossview.raycast import OCCLUSION_REL_TOL, surface_points, visible_from
from scenegen.crossview.rectify import rectification_map, rectify
from scenegen.crossview.targets import board_view_truth
from scenegen.crossview.twoview import TwoView, plane_homography, plane_in_camera

ROOT = "crossview"
INDEX = f"{ROOT}/index.json"


def corr_path(i: str, j: str) -> str:
    return f"{ROOT}/corr/{i}/{j}.exr"


def flow_path(i: str, j: str) -> str:
    return f"{ROOT}/flow/{i}/{j}.flo"


def twoview_path(i: str, j: str) -> str:
    return f"{ROOT}/twoview/{i}/{j}.json"


def matches_path(i: str, j: str, kind: str) -> str:
    return f"{ROOT}/matches/{i}/{j}_{kind}.npy"


def stereo_dir(left_view: str) -> str:
    return f"{ROOT}/stereo/{left_view}"


def targets_path(view: str) -> str:
    return f"{ROOT}/targets/{view}.json"


@dataclass(frozen=True)
class CrossviewSummary:
    pairs: int
    flows: int
    stereo_frames: int
    files: int


# --- pair selection -----------------------------------------------------------------------
def streams(views) -> dict:
    """Views grouped into camera streams: same view set and rig member, in frame order."""
    out: dict = {}
    for v in views:
        out.setdefault((v.view_set, v.rig_member), []).append(v)
    return {k: sorted(vs, key=lambda v: v.frame_index) for k, vs in out.items()}


def consecutive_pairs(views) -> list[tuple[str, str]]:
    """Consecutive frames of each stream, then the members of each rig frame (first member with
    each other member), in the run's view order."""
    pairs = []
    for vs in streams(views).values():
        pairs += [(a.name, b.name) for a, b in zip(vs, vs[1:])]
    frames: dict = {}
    for v in views:
        if v.rig is not None:
            frames.setdefault((v.view_set, v.frame_index), []).append(v.name)
    for names in frames.values():
        pairs += [(names[0], other) for other in names[1:]]
    order = {v.name: k for k, v in enumerate(views)}
    return sorted(set(pairs), key=lambda p: (order[p[0]], order[p[1]]))


def select_pairs(mode, views) -> list[tuple[str, str]]:
    if mode == "none":
        return []
    if mode == "all":
        return [(a.name, b.name) for a, b in itertools.combinations(views, 2)]
    if mode == "consecutive":
        return consecutive_pairs(views)
    return [tuple(p) for p in mode]


def _seed(base: int, *parts: str) -> int:
    h = hashlib.sha256(":".join([str(base), *parts]).encode()).digest()
    return int.from_bytes(h[:4], "little")


# --- the stage ----------------------------------------------------------------------------
class _Context:
    def __init__(self, spec, views, built, writer):
        from scenegen.render.truth import truth_pass

        self._truth_pass = truth_pass
        self.spec, self.built, self.writer = spec, built, writer
        self.views = {v.name: v for v in views}
        self._points: dict = {}
        self._corr: dict = {}
        self.files: list[str] = []

    def camera(self, name):
        v = self.views[name]
        return self.built.cameras[v.camera], v.cam_from_world

    def points(self, name) -> np.ndarray:
        """(H, W, 3) float64 world truth points of a view (NaN = no surface)."""
        if name not in self._points:
            from scenegen.pipeline import rolling_shutter_rows

            cam, pose = self.camera(name)
            # the same call as the view's stored truth (per-row poses for a rolling shutter)
            t = self._truth_pass(self.built.scene, cam, pose, self.built.id_tables,
                                 row_poses=rolling_shutter_rows(self.built, self.views[name]))
            self._points[name] = np.where(t["valid"][..., None], t["points_world"], np.nan)
        return self._points[name]

    def visible_fn(self):
        scene = self.built.scene
        return lambda center, pts: visible_from(scene, center, pts)

    def corr(self, i, j) -> cc.Correspondence:
        if (i, j) not in self._corr:
            cam_j, pose_j = self.camera(j)
            self._corr[(i, j)] = cc.correspond(self.points(i), cam_j, pose_j, self.visible_fn())
        return self._corr[(i, j)]

    def write(self, rel: str, data: bytes) -> None:
        self.writer.write_file(rel, data)
        self.files.append(rel)


def _homographies(ctx: _Context, i: str, j: str) -> dict:
    """Plane homographies (undistorted pixels i -> j) of every planar object: planes and boards."""
    from scenegen.spec import model as m

    cam_i, pose_i = ctx.camera(i)
    cam_j, pose_j = ctx.camera(j)
    rel = pose_j @ pose_i.inverse()
    out = {}
    for obj in ctx.spec.objects:
        if not isinstance(obj.geometry, (m.Plane, m.CheckerboardTarget, m.CharucoTarget, m.ArucoGridTarget)):
            continue
        wfo = obj.transform.world_from_object
        n_i, d_i = plane_in_camera(pose_i, wfo.R[:, 2], wfo.t)  # object z = 0 plane, normal +z
        if abs(d_i) < 1e-12:
            continue  # camera i lies in the plane: no homography
        H = plane_homography(cam_i.K, cam_j.K, rel, n_i, d_i)
        out[obj.name] = {"H": H.tolist(), "plane_normal_i": n_i.tolist(), "plane_distance_i_m": d_i}
    return out


def _stereo_frames(views, rigs) -> list[tuple[str, str]]:
    """(left view, right view) of every frame of a stereo rig, in order."""
    frames: dict = {}
    for v in views:
        if v.rig is not None and rigs[v.rig].type == "stereo":
            frames.setdefault((v.view_set, v.frame_index), {})[v.rig_member] = v.name
    return [(f["left"], f["right"]) for f in frames.values() if "left" in f and "right" in f]


def _render_rectified(ctx, sensor_camera_name, camera, pose, *, spp, seed, light_scales=None):
    import mitsuba as mi

    from scenegen.render.scene import set_lighting

    set_lighting(ctx.built, light_scales)
    sensor = ctx.built.sensors[sensor_camera_name]
    sensor.set_camera(camera, pose)
    img = mi.render(ctx.built.scene, sensor=sensor, spp=int(spp), seed=int(seed))
    return np.array(img, dtype=np.float32)[..., :3]


def _stereo(ctx: _Context, left: str, right: str, *, encode_image, spp: int, seed: int) -> dict:
    cam_l, pose_l = ctx.camera(left)
    cam_r, pose_r = ctx.camera(right)
    rect = rectify(cam_l, pose_l, cam_r, pose_r)
    rc = rect.camera
    base = stereo_dir(left)
    vis = ctx.visible_fn()
    out = {"left_view": left, "right_view": right, "dir": base}
    truths = {}
    for side, pose in (("left", rect.cam_left_from_world), ("right", rect.cam_right_from_world)):
        lin = _render_rectified(ctx, ctx.views[left].camera, rc, pose, spp=spp, seed=_seed(seed, left, side),
                                light_scales=ctx.views[left].light_scales)  # both sides: the left view's lighting
        ctx.write(f"{base}/{side}.png", sio.encode_png(encode_image(lin)))
        ctx.write(f"{base}/{side}_linear.exr", sio.encode_exr(sio.pack_channels("", lin, "RGB")))
        t = ctx._truth_pass(ctx.built.scene, rc, pose, ctx.built.id_tables)
        truths[side] = (np.where(t["valid"][..., None], t["points_world"], np.nan), t["depth_z"])
    for side, other_pose in (("left", rect.cam_right_from_world), ("right", rect.cam_left_from_world)):
        pts, depth = truths[side]
        d = dsp.disparity_from_depth(depth, rect.f, rect.baseline_m)
        c = cc.correspond(pts, rc, other_pose, vis)
        noc = c.state == cc.VISIBLE
        allm = np.isfinite(d)
        ctx.write(f"{base}/disp_{side}.pfm", dsp.encode_pfm(d))
        ctx.write(f"{base}/disp_{side}_occ.png", sio.encode_png(dsp.encode_kitti(d, allm)))
        ctx.write(f"{base}/disp_{side}_noc.png", sio.encode_png(dsp.encode_kitti(d, noc)))
        ctx.write(f"{base}/corr_{side}.exr", sio.encode_exr(cc.encode_correspondence(c)))
    for side, raw, R in (("left", cam_l, rect.R1), ("right", cam_r, rect.R2)):
        mp = rectification_map(raw, R, rc)
        ctx.write(f"{base}/map_{side}.exr", sio.encode_exr(
            {"map_x": mp[..., 0].astype(np.float32), "map_y": mp[..., 1].astype(np.float32)}))
    calib = rect.to_dict()
    calib.update({"left_view": left, "right_view": right,
                  "raw_left": {"camera": cam_l.to_dict(), "cam_from_world": pose_l.to_dict()},
                  "raw_right": {"camera": cam_r.to_dict(), "cam_from_world": pose_r.to_dict()},
                  "twoview_raw": TwoView.of(cam_l, pose_l, cam_r, pose_r).to_dict()})
    ctx.write(f"{base}/calib.json", sio.encode_json(calib))
    return out


def run_crossview(spec, views, built, writer, *, encode_image: Callable[[np.ndarray], np.ndarray],
                  spp: int, seed: int) -> CrossviewSummary | None:
    """Write the cross-view truth ``spec.crossview`` asks for (nothing when it is None).

    ``views``: the resolved views; ``built``: the loaded scene; ``writer``: the open
    DatasetWriter; ``encode_image``: linear float32 RGB -> the uint8/uint16 image the pipeline
    writes for its views (used for the rectified renders); ``spp``, ``seed``: render settings.
    """
    cfg = getattr(spec, "crossview", None)
    if cfg is None:
        return None
    done = [v for v in views if writer.is_complete(v.name)]
    ctx = _Context(spec, done, built, writer)
    names = set(ctx.views)
    pairs = [p for p in select_pairs(cfg.pairs, views) if p[0] in names and p[1] in names]
    index = {"format": "scenegen-crossview", "format_version": 1,
             "occlusion_rel_tol": OCCLUSION_REL_TOL,
             "state_codes": {str(k): v for k, v in cc.STATE_NAMES.items()},
             "match_columns": list(MATCH_COLUMNS), "match_labels": {str(k): v for k, v in LABELS.items()},
             "pairs": [], "flow": [], "stereo": [], "targets": []}
    for a, b in pairs:
        entry = {"i": a, "j": b}
        for i, j in ((a, b), (b, a)):
            ctx.write(corr_path(i, j), sio.encode_exr(cc.encode_correspondence(ctx.corr(i, j))))
        cam_a, pose_a = ctx.camera(a)
        cam_b, pose_b = ctx.camera(b)
        tv = TwoView.of(cam_a, pose_a, cam_b, pose_b).to_dict()
        tv.update({"i": a, "j": b, "homographies": _homographies(ctx, a, b),
                   "pixels": "undistorted OpenCV pixels: x = K (X/Z, Y/Z, 1); x_j^T F x_i = 0"})
        ctx.write(twoview_path(a, b), sio.encode_json(tv))
        if cfg.matches is not None:
            ms = cfg.matches
            p = MatchParams(count=ms.count, sigma_px=ms.sigma_px, outlier_fraction=ms.outlier_fraction,
                            near_miss_fraction=ms.near_miss_fraction, near_miss_px=tuple(ms.near_miss_px),
                            seed=_seed(ms.seed, a, b))
            c = ctx.corr(a, b)
            rows = synthetic_matches(c.uv, c.visible, cam_b.width, cam_b.height, p)
            ctx.write(matches_path(a, b, "synthetic"), sio.encode_npy(rows))
            entry["synthetic_matches"] = {"count": len(rows), "seed": p.seed}
        if cfg.sift:
            pi, pj = sift_matches(_image(writer, a), _image(writer, b), cfg.sift_ratio)
            P = surface_points(built.scene, cam_a, pose_a, pi)
            c = cc.correspond(P.reshape(-1, 1, 3), cam_b, pose_b, ctx.visible_fn())
            rows = label_real_matches(pi, pj, c.uv.reshape(-1, 2), c.state.ravel() == cc.VISIBLE, cfg.sift_inlier_px)
            ctx.write(matches_path(a, b, "sift"), sio.encode_npy(rows))
            entry["sift_matches"] = {"count": len(rows), "inliers": int((rows[:, 6] == 0).sum()),
                                     "ratio": cfg.sift_ratio, "inlier_px": cfg.sift_inlier_px}
        index["pairs"].append(entry)
    if cfg.flow:  # adjacent frames of the full stream, both complete: stable across --frames runs
        for vs in streams(views).values():
            for va, vb in zip(vs, vs[1:]):
                if va.name not in names or vb.name not in names:
                    continue
                for i, j in ((va.name, vb.name), (vb.name, va.name)):
                    ctx.write(flow_path(i, j), encode_flo(cc.flow_field(ctx.corr(i, j))))
                index["flow"].append({"i": va.name, "j": vb.name})
    if cfg.stereo:
        for left, right in _stereo_frames(done, spec.rigs):
            index["stereo"].append(_stereo(ctx, left, right, encode_image=encode_image, spp=spp, seed=seed))
    if cfg.targets and built.boards:
        for v in done:
            cam, pose = ctx.camera(v.name)
            boards = {name: board_view_truth(board, wfb, cam, pose, ctx.visible_fn())
                      for name, (board, wfb) in built.boards.items()}
            ctx.write(targets_path(v.name), sio.encode_json({"view": v.name, "boards": boards}))
            index["targets"].append(v.name)
    index["files"] = sorted(ctx.files)
    if len(done) == len(views):  # the index describes the whole run; partial runs write none
        writer.write_file(INDEX, sio.encode_json(index))
    return CrossviewSummary(len(index["pairs"]), len(index["flow"]), len(index["stereo"]), len(ctx.files) + 1)


def _image(writer, view: str) -> np.ndarray:
    from scenegen.dataset import view_paths

    return sio.read_png(writer.root / view_paths(view)["image"])
