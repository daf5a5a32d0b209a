"""A scenegen dataset opened for evaluation: :class:`DatasetTruth`, the evaluator's policy over a
:class:`scenegen.dataset.Dataset` (the only code that knows a dataset's paths and files,
docs/dataset_format.md and docs/crossview.md). Every accessor of the Dataset is reached through it
(``truth.image(view)``, ``truth.view_info(view)``, ``truth.scene_name``): a new truth accessor is
written once, in scenegen.dataset. What this module adds is recon_eval's policy only:

* every problem is an :class:`recon_eval.errors.InputError` naming the dataset file and field (a
  view that is not complete lists the complete ones); truth the dataset does not hold (no
  cross-view truth, no correspondences for a pair, no board) is a
  :class:`recon_eval.errors.NotApplicable`;
* NaN is the missing marker: depth (the ``depth_z`` truth; the file stores +inf where the pixel
  centre's ray hit nothing), flow, disparity;
* the dataset's visibility: exact correspondences between two views are the truth points of view 1
  projected into view 2, kept where the dataset's ray-cast visibility
  (``crossview/corr/<view1>/<view2>.exr``, state VISIBLE) says view 2 sees them, never re-derived;
* what an evaluation needs in its own terms: poses as :class:`recon_eval.metrics.poses.Poses`,
  the disparity of a rectified stereo pair (``fx * baseline / depth_z``, checked rectified), the
  world-frame meshes concatenated, the calibration boards, held-out truth points at pixels.
"""
from __future__ import annotations

import inspect
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.poses import Poses
from scenegen.dataset import CAMERAS, MANIFEST, Dataset, DatasetError
from scenegen.dataset.crossview import VISIBLE, Correspondence, CrossviewIndex, MatchSet
from scenegen.dataset.codecs import TrackSet
from scenegen.dataset.layout import (CROSSVIEW_INDEX, MATCH_KINDS, MESHES_DIR, SEQUENCE_INDEX, correspondence_path,
                                     flow_path, mesh_path, stereo_path, view_paths)
from scenegen.geometry.conventions import in_image

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
    """A scenegen dataset opened for evaluation. ``views``: complete views in the run's order;
    ``dataset``: the :class:`scenegen.dataset.Dataset`. Any other attribute is the Dataset's own,
    its methods called through :meth:`read` (the evaluator's errors; a first argument ``view``
    checked by :meth:`check_view` first)."""

    def __init__(self, dataset: Dataset, views: tuple):
        self.dataset = dataset
        self.root = Path(dataset.root)
        self.views = tuple(views)

    def __repr__(self) -> str:
        return f"DatasetTruth({str(self.root)!r}, {len(self.views)} views)"

    def __getattr__(self, name: str):
        if name.startswith("_") or name == "dataset":  # not the Dataset's private parts (nor during unpickling)
            raise AttributeError(name)
        attr = getattr(self.dataset, name)
        if not callable(attr):
            return attr
        takes_view = next(iter(inspect.signature(attr).parameters), None) == "view"

        def accessor(*args, **kwargs):
            if takes_view and args:
                self.check_view(args[0])
            return self.read(attr, *args, **kwargs)
        accessor.__doc__ = attr.__doc__
        return accessor

    def read(self, accessor, *args, **kwargs):
        """``accessor(*args, **kwargs)`` of the scenegen reader (the Dataset's, or its crossview,
        sequence or streams reader's), its DatasetError (which names the file) an InputError, a
        KeyError (an entry cameras.json lacks) an InputError naming cameras.json."""
        try:
            return accessor(*args, **kwargs)
        except DatasetError as exc:
            raise InputError(str(exc)) from None
        except KeyError as exc:
            raise InputError(f"{self.root / CAMERAS}: {exc.args[0]}") from None

    # --- the scene
    def object_id(self, name: str) -> int:
        try:
            return self.dataset.object_id(name)
        except KeyError as exc:
            raise InputError(f"{self.root / CAMERAS}: spec.objects: {exc.args[0]}") from None

    def boards(self) -> dict:
        """name -> (geometry dict from the spec, board truth dict from scene/targets/<name>.json)
        of every calibration board (:data:`BOARD_KINDS`), in spec order."""
        out = {}
        for obj in self.objects:
            geo = obj.get("geometry", {})
            if geo.get("kind") in BOARD_KINDS:
                out[obj["name"]] = (geo, self.read(self.dataset.target, obj["name"]))
        return out

    def mesh(self):
        """All world-frame meshes concatenated: (vertices (V, 3) float64 m, faces (F, 3) int64)."""
        names = self.dataset.mesh_names
        if not names:
            raise InputError(f"{self.root / MANIFEST}: files: no {MESHES_DIR}/*.ply in this dataset")
        Vs, Fs, off = [], [], 0
        for n in names:
            try:
                m = self.dataset.mesh(n)
            except DatasetError as exc:
                raise InputError(str(exc)) from None
            except Exception as exc:  # trimesh raises many types on malformed files
                raise InputError(f"{self.dataset.path(mesh_path(n))}: cannot read ({exc})") from None
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
            return self.dataset.camera(view)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{self.root / CAMERAS}: views.{view}.camera / cam_from_world: {exc}") from None

    def stereo_partner(self, view: str) -> str:
        """The other member of ``view``'s rig at the same frame (exactly one must exist)."""
        info = self.view_info(view)
        if info.get("rig") is None:
            raise InputError(f"{self.root / CAMERAS}: views.{view}.rig is null: a free camera has no stereo partner")
        others = self.dataset.rig_partners(view)
        if len(others) != 1:
            raise InputError(f"{self.root / CAMERAS}: rig {info['rig']!r} frame {info.get('frame_index')} has"
                             f" {len(others) + 1} complete views; name the right view explicitly")
        return others[0]

    # --- per-pixel truth
    def depth(self, view: str) -> np.ndarray:
        """Truth z-depth (H, W) float64 metres; NaN where the ray hit nothing."""
        d = self.read(self.dataset.depth_z, self.check_view(view)).astype(np.float64)
        d[~np.isfinite(d)] = np.nan
        return d

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
        P = self.points_world(view).astype(np.float64)  # checks the view
        ok = np.all(np.isfinite(P), axis=-1)
        vv, uu = np.nonzero(ok)
        if len(vv) == 0:
            raise InputError(f"{self.dataset.path(view_paths(view)['truth'])}: no valid pixel (the view sees nothing)")
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
    def require_crossview_index(self) -> CrossviewIndex:
        """The typed index; NotApplicable (saying how to get one) when the dataset has none."""
        try:
            return self.dataset.crossview.require_index()
        except DatasetError as exc:
            if self.dataset.has(CROSSVIEW_INDEX):
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
        if not self.dataset.crossview.has_correspondence(view1, view2):
            raise NotApplicable(f"{self.dataset.path(rel)}: no such file: the dataset has no correspondence truth for "
                                f"views {view1!r} -> {view2!r} (the spec's crossview.pairs must include that pair)")
        return self.read(self.dataset.crossview.correspondence, view1, view2)

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
        seq = self.read(lambda: self.dataset.sequence.index)
        if seq is not None:
            return tuple(p for a, b, _ in seq.pairs for p in ((a, b), (b, a)))
        return tuple(p for i, j in self.require_crossview_index().flow for p in ((i, j), (j, i)))

    def track_streams(self) -> dict:
        """{stream: its frames (view names, in order)} of a sequence's point tracks;
        NotApplicable when the dataset has none."""
        seq = self.read(lambda: self.dataset.sequence.index)
        if seq is None or not seq.streams:
            raise NotApplicable(f"{self.dataset.path(SEQUENCE_INDEX)}: no such file or no point tracks: the dataset is "
                                "not a sequence with 'sequence.tracks'")
        return dict(seq.streams)

    def tracks_truth(self, stream: str) -> TrackSet:
        """The truth point tracks of a camera stream (scenegen.dataset.codecs.tracks)."""
        streams = self.track_streams()
        if stream not in streams:
            raise InputError(f"unknown stream {stream!r}; the dataset's: {', '.join(streams)}")
        return self.read(self.dataset.sequence.tracks, stream)

    def flow_truth(self, view1: str, view2: str):
        """``(flow (H, W, 2) float64 px, states (H, W) uint8 or None, source)`` of view1 -> view2:
        the flow truth the dataset holds for the pair (:meth:`scenegen.dataset.crossview_reader.
        CrossviewTruth.pair_flow`), NaN where the flow is unknown; NotApplicable when it holds none."""
        found = self.read(self.dataset.crossview.pair_flow, self.check_view(view1), self.check_view(view2))
        if found is None:
            raise NotApplicable(f"{self.dataset.path(flow_path(view1, view2))}: no such file, and no correspondence "
                                f"truth for views {view1!r} -> {view2!r}: the dataset holds no flow for this pair")
        flow, states, source = found
        flow = np.array(flow, dtype=np.float64)
        flow[~np.all(np.isfinite(flow), axis=2)] = np.nan
        return flow, states, source

    def truth_fundamental(self, view1: str, view2: str):
        """``(F (3, 3) or None, source)``: the truth F of view1 -> view2 for UNDISTORTED OpenCV pixels
        (:meth:`scenegen.dataset.crossview_reader.CrossviewTruth.fundamental`)."""
        for view in (view1, view2):
            self.camera(view)  # the view and its camera checked, with the evaluator's errors
        return self.read(self.dataset.crossview.fundamental, view1, view2)

    def stereo_image_path(self, left_view: str, side: str) -> Path:
        """The rectified image file of one side of a stereo frame (for tools that read files)."""
        self._stereo(left_view)
        return self.dataset.path(stereo_path(left_view, "image", side))

    def match_sets(self, view1: str, view2: str) -> Iterator[MatchSet]:
        """The labelled match sets of a pair that the dataset holds, synthetic first, then sift."""
        for kind in MATCH_KINDS:
            if self.dataset.crossview.has_matches(view1, view2, kind):
                yield self.read(self.dataset.crossview.matches, view1, view2, kind)

    def stereo_left_views(self) -> tuple:
        """Left views of the rectified stereo frames, in index order (NotApplicable without an index)."""
        return tuple(left for left, _ in self.require_crossview_index().stereo)

    def stereo_images(self, left_view: str) -> tuple:
        """(left, right) rectified images (H, W, 3) RGB or (H, W), uint8/uint16."""
        frame = self._stereo(left_view)
        return self.read(frame.image, "left"), self.read(frame.image, "right")

    def stereo_disparity(self, left_view: str, side: str = "left") -> np.ndarray:
        """Rectified truth disparity (H, W) float64 px of one side, NaN where there is no surface."""
        d = self.read(self._stereo(left_view).disparity, side).astype(np.float64)
        d[np.isinf(d)] = np.nan
        return d

    def stereo_noc_mask(self, left_view: str, side: str = "left") -> np.ndarray:
        """(H, W) bool: rectified pixels of one side with a surface the other side sees (KITTI noc)."""
        return self.read(self._stereo(left_view).disparity_kitti, side, "noc")[1]

    def stereo_ir_images(self, left_view: str, projector: bool = True) -> tuple:
        """(left, right) rectified monochrome IR images (H, W) of an active stereo frame."""
        frame = self._stereo(left_view)
        return self.read(frame.ir_image, "left", projector), self.read(frame.ir_image, "right", projector)

    def stereo_ir_invalid(self, left_view: str, side: str = "left") -> np.ndarray:
        """(H, W) uint8 active IR stereo invalid bits (0 = valid; scenegen.dataset.ir_stereo)."""
        return self.read(self._stereo(left_view).ir_invalid, side)

    def _stereo(self, left_view: str):
        try:
            return self.dataset.crossview.stereo(left_view)
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
