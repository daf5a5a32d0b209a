"""A scenegen dataset opened for evaluation: a thin view over :class:`scenegen.dataset.Dataset`
(the only code that knows a dataset's paths, docs/dataset_format.md and docs/crossview.md) in
recon_eval's conventions:

* poses: cam_from_world from cameras.json (OpenCV axes, metres), named by view;
* depth: the ``depth_z`` truth, NaN where the pixel centre's ray hit nothing (the file stores
  +inf there; NaN is recon_eval's missing marker);
* disparity of a rectified stereo pair: ``fx * baseline / depth_z`` for the left view (checked:
  same pinhole intrinsics, same rotation, baseline along the camera x axis);
* world-frame points seen at given pixels (held-out truth points for calibration and PnP);
* the world-frame meshes, concatenated (for exact point-to-triangle distances);
* exact, visible correspondences between two views: truth points of view 1 projected into view 2,
  kept where the dataset's ray-cast visibility (``crossview/corr/<view1>/<view2>.exr``, state
  VISIBLE) says view 2 sees them: the dataset's one visibility truth, never re-derived here;
* the cross-view truth: the typed index, two-view geometry, labelled match sets, rectified stereo
  frames, calibration boards.

Every problem is an :class:`recon_eval.errors.InputError` naming the dataset file and field; truth
the dataset does not hold (no cross-view truth, no correspondences for a pair, no board) is a
:class:`recon_eval.errors.NotApplicable`.
"""
from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.poses import Poses
from scenegen.dataset import CAMERAS, MANIFEST, Dataset, DatasetError
from scenegen.dataset.crossview import VISIBLE, Correspondence, CrossviewIndex, MatchSet
from scenegen.dataset.crossview_reader import TwoViewTruth
from scenegen.dataset.codecs import TrackSet
from scenegen.dataset.layout import (CROSSVIEW_INDEX, MATCH_KINDS, MESHES_DIR, SEQUENCE_INDEX, correspondence_path,
                                     flow_path, mesh_path, motion_path, stereo_path, twoview_path, view_paths)
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.conventions import in_image
from scenegen.geometry.twoview import fundamental

#: Rectification tolerances of :meth:`DatasetTruth.disparity`: rotations equal to 1e-9 (JSON
#: round-trips float64 exactly; the renderer places both members by the same rig rotation), and
#: the baseline's y and z components below 1e-9 of its length.
RECTIFIED_TOL = 1e-9
#: Spec geometry kinds of the calibration boards (truth points in scene/targets/<name>.json).
BOARD_KINDS = ("checkerboard", "charuco", "aruco_grid", "aruco")


def is_dataset(path) -> bool:
    """True if ``path`` is a directory holding a scenegen dataset (manifest.json and cameras.json)."""
    p = Path(path)
    return p.is_dir() and (p / MANIFEST).is_file() and (p / CAMERAS).is_file()


class DatasetTruth:
    """A scenegen dataset opened for evaluation. ``views``: complete views in the run's order."""

    def __init__(self, dataset: Dataset, views: tuple):
        self._ds = dataset
        self.root = Path(dataset.root)
        self.views = tuple(views)

    def __repr__(self) -> str:
        return f"DatasetTruth({str(self.root)!r}, {len(self.views)} views)"

    def _read(self, fn, *args):
        """``fn(*args)`` of the scenegen reader, its DatasetError (which names the file) as InputError."""
        try:
            return fn(*args)
        except DatasetError as exc:
            raise InputError(str(exc)) from None

    # --- the scene
    @property
    def scene_name(self) -> str:
        """The scene name recorded in cameras.json (``spec.name``), else the folder name."""
        return self._ds.scene_name

    @property
    def objects(self) -> list:
        """The spec's objects (resolved dicts, spec order; object ``k`` has object_id ``k + 1``)."""
        return self._ds.objects

    def object_id(self, name: str) -> int:
        try:
            return self._ds.object_id(name)
        except KeyError as exc:
            raise InputError(f"{self.root / CAMERAS}: spec.objects: {exc.args[0]}") from None

    def boards(self) -> dict:
        """name -> (geometry dict from the spec, board truth dict from scene/targets/<name>.json)
        of every calibration board (:data:`BOARD_KINDS`), in spec order."""
        out = {}
        for obj in self.objects:
            geo = obj.get("geometry", {})
            if geo.get("kind") in BOARD_KINDS:
                out[obj["name"]] = (geo, self._read(self._ds.target, obj["name"]))
        return out

    def mesh(self):
        """All world-frame meshes concatenated: (vertices (V, 3) float64 m, faces (F, 3) int64)."""
        names = self._ds.mesh_names
        if not names:
            raise InputError(f"{self.root / MANIFEST}: files: no {MESHES_DIR}/*.ply in this dataset")
        Vs, Fs, off = [], [], 0
        for n in names:
            try:
                m = self._ds.mesh(n)
            except DatasetError as exc:
                raise InputError(str(exc)) from None
            except Exception as exc:  # trimesh raises many types on malformed files
                raise InputError(f"{self._ds.path(mesh_path(n))}: cannot read ({exc})") from None
            V = np.asarray(m.vertices, dtype=np.float64).reshape(-1, 3)
            F = np.asarray(getattr(m, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
            Vs.append(V)
            Fs.append(F + off)
            off += len(V)
        return np.concatenate(Vs), np.concatenate(Fs)

    # --- views, poses and cameras
    def check_view(self, view: str) -> str:
        """``view`` if it is a complete view of the dataset, else an InputError listing them."""
        if view not in self.views:
            raise InputError(f"{self.root / MANIFEST}: view {view!r} is not a complete view of this dataset"
                             f" (complete views: {', '.join(self.views[:8])}{' ...' if len(self.views) > 8 else ''})")
        return view

    @property
    def poses(self) -> Poses:
        """cam_from_world of every complete view, named by view name."""
        Rs, ts = [], []
        for v in self.views:
            _, pose = self.camera(v)
            Rs.append(pose.R)
            ts.append(pose.t)
        return Poses(self.views, np.asarray(Rs).reshape(-1, 3, 3), np.asarray(ts).reshape(-1, 3))

    def camera(self, view: str):
        """(scenegen.geometry.camera.Camera, cam_from_world: scenegen.geometry.pose.Rigid3) of a view."""
        self.check_view(view)
        try:
            return self._ds.camera(view)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{self.root / CAMERAS}: views.{view}.camera / cam_from_world: {exc}") from None

    def view_info(self, view: str) -> dict:
        """The view's raw cameras.json entry (camera_name, rig, frame_index, view_set, lights...)."""
        self.check_view(view)
        try:
            return self._ds.view_info(view)
        except KeyError as exc:
            raise InputError(f"{self.root / CAMERAS}: {exc.args[0]}") from None

    def views_of_camera(self, camera_name: str) -> tuple:
        """Complete views taken with the spec camera ``camera_name``, in view order."""
        return tuple(v for v in self.views if self.view_info(v).get("camera_name") == camera_name)

    def stereo_partner(self, view: str) -> str:
        """The other member of ``view``'s rig at the same frame (exactly one must exist)."""
        info = self.view_info(view)
        if info.get("rig") is None:
            raise InputError(f"{self.root / CAMERAS}: views.{view}.rig is null: a free camera has no stereo partner")
        others = self._ds.rig_partners(view)
        if len(others) != 1:
            raise InputError(f"{self.root / CAMERAS}: rig {info['rig']!r} frame {info.get('frame_index')} has"
                             f" {len(others) + 1} complete views; name the right view explicitly")
        return others[0]

    # --- per-pixel truth
    def image(self, view: str) -> np.ndarray:
        """The rendered image (H, W, 3) RGB or (H, W), uint8/uint16."""
        return self._read(self._ds.image, self.check_view(view))

    def image_path(self, view: str) -> Path:
        """The rendered image's file (images/<view>.png), for tools that read files."""
        return self._ds.path(view_paths(self.check_view(view))["image"])

    def depth(self, view: str) -> np.ndarray:
        """Truth z-depth (H, W) float64 metres; NaN where the ray hit nothing."""
        d = self._read(self._ds.depth_z, self.check_view(view)).astype(np.float64)
        d[~np.isfinite(d)] = np.nan
        return d

    def points_world(self, view: str) -> np.ndarray:
        """Truth hit points (H, W, 3) float64 metres, world frame; NaN on misses."""
        return self._read(self._ds.points_world, self.check_view(view)).astype(np.float64)

    def object_ids(self, view: str) -> np.ndarray:
        """(H, W) uint32 object id of each pixel centre's hit (spec object k is k + 1; 0 = none)."""
        return self._read(self._ds.truth, self.check_view(view))[TruthKind.OBJECT_ID]

    def disparity(self, left: str, right: str | None = None) -> np.ndarray:
        """Truth disparity (H, W) float64 px of the rectified pair (left, right):
        ``d = fx * B / depth_z`` with B the baseline (metres), NaN on misses. Raises unless the pair
        is rectified: both pinhole with equal intrinsics and size, equal rotations, and the right
        camera displaced along the left camera's +x axis (B > 0)."""
        right = self.stereo_partner(left) if right is None else self.check_view(right)
        (c1, p1), (c2, p2) = self.camera(left), self.camera(right)
        where = f"{self.root / CAMERAS}: views {left!r}, {right!r}"
        if c1.model != "pinhole" or c2.model != "pinhole" or c1 != c2:
            raise InputError(f"{where}: camera: disparity truth needs two identical pinhole cameras (rectified)")
        if not np.allclose(p1.R, p2.R, atol=RECTIFIED_TOL, rtol=0):
            raise InputError(f"{where}: cam_from_world.R differ: the pair is not rectified")
        # right camera centre in the left camera frame
        c_right_in_left = p1.apply(p2.inverse().t[None])[0]
        B = float(np.linalg.norm(c_right_in_left))
        if not (c_right_in_left[0] > 0 and np.all(np.abs(c_right_in_left[1:]) <= RECTIFIED_TOL * B)):
            raise InputError(f"{where}: cam_from_world.t: the right camera is not on the left camera's +x axis"
                             f" (offset {c_right_in_left.tolist()} m)")
        with np.errstate(divide="ignore"):
            return c1.fx * B / self.depth(left)

    def _pixel_sample(self, view: str, max_points: int, seed: int):
        """(rows (N,), columns (N,), world points (N, 3)) of up to ``max_points`` valid pixel
        centres, drawn uniformly without replacement (seeded), in row-major order."""
        P = self.points_world(view)
        ok = np.all(np.isfinite(P), axis=-1)
        vv, uu = np.nonzero(ok)
        if len(vv) == 0:
            raise InputError(f"{self._ds.path(view_paths(view)['truth'])}: no valid pixel (the view sees nothing)")
        pick = np.random.default_rng(seed).permutation(len(vv))[:max_points]
        pick.sort()
        vv, uu = vv[pick], uu[pick]
        return vv, uu, P[vv, uu]

    def points_at_pixels(self, view: str, max_points: int = 5000, seed: int = 0):
        """Held-out truth: up to ``max_points`` valid pixel centres (N, 2) OpenCV px, chosen
        uniformly without replacement (seeded), and their world points (N, 3) metres."""
        vv, uu, X = self._pixel_sample(view, max_points, seed)
        return np.stack([uu, vv], axis=1).astype(np.float64), X

    # --- cross-view truth
    @property
    def crossview_index(self) -> CrossviewIndex | None:
        """The typed crossview/index.json, or None when the run wrote no cross-view truth."""
        return self._read(lambda: self._ds.crossview.index)

    def require_crossview_index(self) -> CrossviewIndex:
        """The typed index; NotApplicable (saying how to get one) when the dataset has none."""
        try:
            return self._ds.crossview.require_index()
        except DatasetError as exc:
            if self._ds.has(CROSSVIEW_INDEX):
                raise InputError(str(exc)) from None
            raise NotApplicable(str(exc)) from None

    def crossview_pairs(self) -> tuple:
        """(i, j) of every pair with correspondence truth, in index order (NotApplicable without
        an index; possibly empty)."""
        return self.require_crossview_index().pairs

    def correspondence(self, view1: str, view2: str) -> Correspondence:
        """The dense correspondences of view1's pixels in view2 with their ray-cast visibility;
        NotApplicable naming the file when the dataset has none for this pair."""
        self.check_view(view1)
        self.check_view(view2)
        rel = correspondence_path(view1, view2)
        if not self._ds.crossview.has_correspondence(view1, view2):
            raise NotApplicable(f"{self._ds.path(rel)}: no such file: the dataset has no correspondence truth for "
                                f"views {view1!r} -> {view2!r} (the spec's crossview.pairs must include that pair)")
        return self._read(self._ds.crossview.correspondence, view1, view2)

    def correspondences(self, view1: str, view2: str, max_points: int = 20000, seed: int = 0):
        """Exact, visible correspondences (x1 (N, 2), x2 (N, 2)) OpenCV px: the truth points of up
        to ``max_points`` of ``view1``'s pixel centres (seeded, :meth:`points_at_pixels`) projected
        into ``view2`` (its camera model), kept where inside view 2's image and VISIBLE in the
        dataset's correspondence states (:meth:`correspondence`)."""
        vv, uu, X = self._pixel_sample(view1, max_points, seed)
        visible = self.correspondence(view1, view2).state[vv, uu] == VISIBLE
        cam2, pose2 = self.camera(view2)
        x2, ok = cam2.project(pose2.apply(X), return_valid=True)
        ok &= np.all(np.isfinite(x2), axis=1) & in_image(x2, cam2.width, cam2.height) & visible
        x1 = np.stack([uu, vv], axis=1).astype(np.float64)
        return x1[ok], x2[ok]

    def flow_pairs(self) -> tuple:
        """(i, j) of every flow pair the dataset holds, both directions, in index order: a
        sequence's frame pairs (every flow step, moving objects included) when it is one, else the
        consecutive frames of the cross-view index; NotApplicable without either index."""
        seq = self._read(lambda: self._ds.sequence.index)
        if seq is not None:
            return tuple(p for a, b, _ in seq.pairs for p in ((a, b), (b, a)))
        return tuple(p for i, j in self.require_crossview_index().flow for p in ((i, j), (j, i)))

    def track_streams(self) -> dict:
        """{stream: its frames (view names, in order)} of a sequence's point tracks;
        NotApplicable when the dataset has none."""
        seq = self._read(lambda: self._ds.sequence.index)
        if seq is None or not seq.streams:
            raise NotApplicable(f"{self._ds.path(SEQUENCE_INDEX)}: no such file or no point tracks: the dataset is "
                                "not a sequence with 'sequence.tracks'")
        return dict(seq.streams)

    def tracks_truth(self, stream: str) -> TrackSet:
        """The truth point tracks of a camera stream (scenegen.dataset.codecs.tracks)."""
        streams = self.track_streams()
        if stream not in streams:
            raise InputError(f"unknown stream {stream!r}; the dataset's: {', '.join(streams)}")
        return self._read(self._ds.sequence.tracks, stream)

    def flow_truth(self, view1: str, view2: str):
        """``(flow (H, W, 2) float64 px, states (H, W) uint8 or None, source)`` of view1 -> view2:
        a sequence's motion truth of the pair (flow and occlusion states at view2's time), else
        the dataset's flow file when it has one (consecutive frames), else the correspondence
        field ``uv - pixel`` of a crossview pair; the occlusion states from the correspondence file
        when the dataset has it (None otherwise). NaN where the flow is unknown."""
        self.check_view(view1)
        self.check_view(view2)
        if self._ds.has(motion_path(view1, view2)):  # a sequence's frame pair, moving objects too
            m = self._read(self._ds.sequence.motion, view1, view2)
            flow = np.array(m.flow, dtype=np.float64)
            flow[~np.all(np.isfinite(flow), axis=2)] = np.nan
            return flow, m.state, str(motion_path(view1, view2))
        has_corr = self._ds.crossview.has_correspondence(view1, view2)
        corr = self._read(self._ds.crossview.correspondence, view1, view2) if has_corr else None
        if self._ds.has(flow_path(view1, view2)):
            flow = self._read(self._ds.crossview.flow, view1, view2).astype(np.float64)
            source = str(flow_path(view1, view2))
        elif corr is not None:
            H, W = corr.shape
            grid = np.stack(np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64)), -1)
            flow, source = corr.uv - grid, str(correspondence_path(view1, view2)) + " (uv - pixel)"
        else:
            raise NotApplicable(f"{self._ds.path(flow_path(view1, view2))}: no such file, and no correspondence truth "
                                f"for views {view1!r} -> {view2!r}: the dataset holds no flow for this pair")
        flow[~np.all(np.isfinite(flow), axis=2)] = np.nan
        return flow, None if corr is None else corr.state, source

    def twoview(self, view1: str, view2: str) -> TwoViewTruth:
        """The two-view geometry of a crossview pair (relative pose, E, F, plane homographies)."""
        return self._read(self._ds.crossview.twoview, self.check_view(view1), self.check_view(view2))

    def truth_fundamental(self, view1: str, view2: str):
        """``(F (3, 3) or None, source)``: the truth F of view1 -> view2 for UNDISTORTED OpenCV pixels,
        the stored ``crossview/twoview/<i>/<j>.json`` when the dataset has it, else
        ``K2^-T [t]x R K1^-1`` of cameras.json; None for a zero baseline (one camera centre)."""
        self.check_view(view1)
        self.check_view(view2)
        if self._ds.has(twoview_path(view1, view2)):
            return self.twoview(view1, view2).F, str(twoview_path(view1, view2))
        (c1, p1), (c2, p2) = self.camera(view1), self.camera(view2)
        rel = p2 @ p1.inverse()
        if np.linalg.norm(rel.t) == 0.0:
            return None, f"{CAMERAS}: one camera centre"
        return fundamental(c1.K, c2.K, rel), f"{CAMERAS}: K2^-T [t]x R K1^-1"

    def stereo_image_path(self, left_view: str, side: str) -> Path:
        """The rectified image file of one side of a stereo frame (for tools that read files)."""
        self._stereo(left_view)
        return self._ds.path(stereo_path(left_view, "image", side))

    def match_sets(self, view1: str, view2: str) -> Iterator[MatchSet]:
        """The labelled match sets of a pair that the dataset holds, synthetic first, then sift."""
        for kind in MATCH_KINDS:
            if self._ds.crossview.has_matches(view1, view2, kind):
                yield self._read(self._ds.crossview.matches, view1, view2, kind)

    def stereo_left_views(self) -> tuple:
        """Left views of the rectified stereo frames, in index order (NotApplicable without an index)."""
        return tuple(left for left, _ in self.require_crossview_index().stereo)

    def stereo_images(self, left_view: str) -> tuple:
        """(left, right) rectified images (H, W, 3) RGB or (H, W), uint8/uint16."""
        frame = self._stereo(left_view)
        return self._read(frame.image, "left"), self._read(frame.image, "right")

    def stereo_disparity(self, left_view: str, side: str = "left") -> np.ndarray:
        """Rectified truth disparity (H, W) float64 px of one side, NaN where there is no surface."""
        d = self._read(self._stereo(left_view).disparity, side).astype(np.float64)
        d[np.isinf(d)] = np.nan
        return d

    def stereo_noc_mask(self, left_view: str, side: str = "left") -> np.ndarray:
        """(H, W) bool: rectified pixels of one side with a surface the other side sees (KITTI noc)."""
        return self._read(self._stereo(left_view).disparity_kitti, side, "noc")[1]

    def _stereo(self, left_view: str):
        try:
            return self._ds.crossview.stereo(left_view)
        except KeyError as exc:
            raise NotApplicable(f"{self.root / CROSSVIEW_INDEX}: stereo: {exc.args[0]}") from None


def read_dataset(path) -> DatasetTruth:
    """Open a scenegen dataset directory for evaluation (manifest checked, complete views only)."""
    p = Path(path)
    if not is_dataset(p):
        raise InputError(f"{p}: not a scenegen dataset (expected a directory with manifest.json and cameras.json)")
    try:
        ds = Dataset(p)
        views = tuple(ds.views)
    except DatasetError as exc:
        raise InputError(str(exc)) from None
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{p / CAMERAS}: unreadable ({type(exc).__name__}: {exc})") from None
    if not views:
        raise InputError(f"{p / MANIFEST}: views: no complete view in this dataset")
    return DatasetTruth(ds, views)
