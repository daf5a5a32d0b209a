"""Our own datasets (``scenegen-dataset``, docs/dataset_format.md) as the truth.

Read through :class:`scenegen.dataset.Dataset` (numpy, OpenCV, OpenEXR; no Mitsuba). What the
metrics need is exposed in recon_eval's conventions:

* poses: ``cam_from_world`` of every *complete* view from cameras.json, named by view name, in the
  run's view order (:class:`recon_eval.poses.Poses`);
* cameras: :class:`scenegen.geometry.camera.Camera` per view (OpenCV pixels, model and distortion);
* depth: ``depth_z`` (H, W) float64 metres from ``truth/<view>.exr``, NaN where the pixel centre's
  ray hit nothing (the file stores +inf there; NaN is recon_eval's missing marker);
* disparity of a rectified stereo pair: ``fx * baseline / depth_z`` for the left view (checked:
  same pinhole intrinsics, same rotation, baseline along the camera x axis);
* world-frame points seen at given pixels (held-out truth points for calibration and PnP);
* the world-frame meshes, concatenated (for exact point-to-triangle distances);
* exact, visible correspondences between two views (from the truth points and the second view's
  depth).

Every problem is an :class:`recon_eval.errors.InputError` naming the dataset file and field.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.poses import Poses

#: Relative depth tolerance of the visibility test in :func:`DatasetTruth.correspondences`: a point
#: of view 1 is visible in view 2 if its depth in view 2 is within this fraction of the truth depth
#: of view 2's nearest pixel centre. The point does not fall on a pixel centre of view 2, so the
#: stored depth there belongs to a neighbouring surface point: on a surface inclined by up to ~80
#: degrees one pixel's footprint changes depth by far less than 1 % at typical focal lengths, while
#: an occluder is a separate surface, usually much nearer.
VISIBILITY_REL_TOL = 0.01
#: Rectification tolerances of :meth:`DatasetTruth.disparity`: rotations equal to 1e-9 (JSON
#: round-trips float64 exactly; the renderer places both members by the same rig rotation), and
#: the baseline's y and z components below 1e-9 of its length.
RECTIFIED_TOL = 1e-9


def is_dataset(path) -> bool:
    """True if ``path`` is a directory holding a scenegen dataset (manifest.json and cameras.json)."""
    p = Path(path)
    return p.is_dir() and (p / "manifest.json").is_file() and (p / "cameras.json").is_file()


@dataclass(frozen=True)
class DatasetTruth:
    """A scenegen dataset opened for evaluation. ``views``: complete views in the run's order."""

    root: Path
    views: tuple
    _ds: object  # scenegen.dataset.Dataset

    # --- poses and cameras
    @property
    def poses(self) -> Poses:
        """cam_from_world of every complete view, named by view name."""
        Rs, ts = [], []
        for v in self.views:
            _, pose = self.camera(v)
            Rs.append(pose.R)
            ts.append(pose.t)
        return Poses(self.views, np.asarray(Rs).reshape(-1, 3, 3), np.asarray(ts).reshape(-1, 3))

    def _check_view(self, view: str) -> str:
        if view not in self.views:
            raise InputError(f"{self.root / 'manifest.json'}: view {view!r} is not a complete view of this dataset"
                             f" (complete views: {', '.join(self.views[:8])}{' ...' if len(self.views) > 8 else ''})")
        return view

    def camera(self, view: str):
        """(scenegen.geometry.camera.Camera, cam_from_world: scenegen.geometry.pose.Rigid3) of a view."""
        self._check_view(view)
        try:
            return self._ds.camera(view)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"{self.root / 'cameras.json'}: views.{view}.camera / cam_from_world: {exc}") from None

    def view_info(self, view: str) -> dict:
        self._check_view(view)
        try:
            return self._ds.view_info(view)
        except KeyError as exc:
            raise InputError(f"{self.root / 'cameras.json'}: {exc.args[0]}") from None

    def views_of_camera(self, camera_name: str) -> tuple:
        """Complete views taken with the spec camera ``camera_name``, in view order."""
        return tuple(v for v in self.views if self.view_info(v).get("camera_name") == camera_name)

    # --- per-pixel truth
    def _truth_channels(self, view: str) -> dict:
        self._check_view(view)
        from scenegen.dataset import codecs as sio

        path = self.root / "truth" / f"{view}.exr"
        if not path.is_file():
            raise InputError(f"{path}: no such file (truth of view {view!r})")
        try:
            return sio.read_exr(path)
        except ValueError as exc:
            raise InputError(str(exc)) from None

    def _channel(self, view: str, name: str) -> np.ndarray:
        ch = self._truth_channels(view)
        if name not in ch:
            raise InputError(f"{self.root / 'truth' / (view + '.exr')}: no channel {name!r} (have {sorted(ch)})")
        return ch[name]

    def depth(self, view: str) -> np.ndarray:
        """Truth z-depth (H, W) float64 metres; NaN where the ray hit nothing."""
        d = self._channel(view, "depth_z").astype(np.float64)
        d[~np.isfinite(d)] = np.nan
        return d

    def points_world(self, view: str) -> np.ndarray:
        """Truth hit points (H, W, 3) float64 metres, world frame; NaN on misses."""
        ch = self._truth_channels(view)
        names = ("P_world.X", "P_world.Y", "P_world.Z")
        missing = [n for n in names if n not in ch]
        if missing:
            raise InputError(f"{self.root / 'truth' / (view + '.exr')}: no channel(s) {missing}")
        return np.stack([ch[n] for n in names], axis=-1).astype(np.float64)

    def image(self, view: str) -> np.ndarray:
        """The rendered image (H, W, 3) RGB or (H, W), uint8/uint16."""
        self._check_view(view)
        try:
            return self._ds.image(view)
        except (OSError, ValueError) as exc:
            raise InputError(f"{self.root / 'images' / (view + '.png')}: {exc}") from None

    def stereo_partner(self, view: str) -> str:
        """The other member of ``view``'s rig at the same frame (exactly one must exist)."""
        info = self.view_info(view)
        rig = info.get("rig")
        if rig is None:
            raise InputError(f"{self.root / 'cameras.json'}: views.{view}.rig is null: a free camera has no stereo partner")
        others = [v for v in self.views if v != view and self.view_info(v).get("rig") == rig
                  and self.view_info(v).get("frame_index") == info.get("frame_index")]
        if len(others) != 1:
            raise InputError(f"{self.root / 'cameras.json'}: rig {rig!r} frame {info.get('frame_index')} has"
                             f" {len(others) + 1} complete views; name the right view explicitly")
        return others[0]

    def disparity(self, left: str, right: str | None = None) -> np.ndarray:
        """Truth disparity (H, W) float64 px of the rectified pair (left, right):
        ``d = fx * B / depth_z`` with B the baseline (metres), NaN on misses. Raises unless the pair
        is rectified: both pinhole with equal intrinsics and size, equal rotations, and the right
        camera displaced along the left camera's +x axis (B > 0)."""
        right = self.stereo_partner(left) if right is None else self._check_view(right)
        (c1, p1), (c2, p2) = self.camera(left), self.camera(right)
        where = f"{self.root / 'cameras.json'}: views {left!r}, {right!r}"
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

    def points_at_pixels(self, view: str, max_points: int = 5000, seed: int = 0):
        """Held-out truth: up to ``max_points`` valid pixel centres (N, 2) OpenCV px, chosen
        uniformly without replacement (seeded), and their world points (N, 3) metres."""
        P = self.points_world(view)
        ok = np.all(np.isfinite(P), axis=-1)
        vv, uu = np.nonzero(ok)
        if len(vv) == 0:
            raise InputError(f"{self.root / 'truth' / (view + '.exr')}: no valid pixel (the view sees nothing)")
        pick = np.random.default_rng(seed).permutation(len(vv))[:max_points]
        pick.sort()
        vv, uu = vv[pick], uu[pick]
        return np.stack([uu, vv], axis=1).astype(np.float64), P[vv, uu]

    def correspondences(self, view1: str, view2: str, max_points: int = 20000, seed: int = 0):
        """Exact, visible correspondences (x1 (N, 2), x2 (N, 2)) OpenCV px: truth points of
        ``view1`` pixel centres projected into ``view2`` (its camera model), kept when inside
        view 2's image and visible there (depth test, :data:`VISIBILITY_REL_TOL`)."""
        x1, X = self.points_at_pixels(view1, max_points=max_points, seed=seed)
        cam2, pose2 = self.camera(view2)
        Xc = pose2.apply(X)
        x2, ok = cam2.project(Xc, return_valid=True)
        ok &= np.all(np.isfinite(x2), axis=1)
        ok &= (x2[:, 0] > -0.5) & (x2[:, 0] < cam2.width - 0.5) & (x2[:, 1] > -0.5) & (x2[:, 1] < cam2.height - 0.5)
        d2 = self.depth(view2)
        vi = np.clip(np.rint(np.nan_to_num(x2[:, 1])), 0, cam2.height - 1).astype(np.int64)
        ui = np.clip(np.rint(np.nan_to_num(x2[:, 0])), 0, cam2.width - 1).astype(np.int64)
        with np.errstate(invalid="ignore"):
            ok &= np.abs(Xc[:, 2] - d2[vi, ui]) <= VISIBILITY_REL_TOL * d2[vi, ui]
        return x1[ok], x2[ok]

    # --- geometry
    def mesh(self):
        """All world-frame meshes concatenated: (vertices (V, 3) float64 m, faces (F, 3) int64)."""
        names = self._ds.mesh_names
        if not names:
            raise InputError(f"{self.root / 'manifest.json'}: files: no scene/meshes/*.ply in this dataset")
        Vs, Fs, off = [], [], 0
        for n in names:
            try:
                m = self._ds.mesh(n)
            except Exception as exc:  # trimesh raises many types on malformed files
                raise InputError(f"{self.root / 'scene' / 'meshes' / (n + '.ply')}: cannot read ({exc})") from None
            V = np.asarray(m.vertices, dtype=np.float64).reshape(-1, 3)
            F = np.asarray(getattr(m, "faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
            Vs.append(V)
            Fs.append(F + off)
            off += len(V)
        return np.concatenate(Vs), np.concatenate(Fs)


def read_dataset(path) -> DatasetTruth:
    """Open a scenegen dataset directory for evaluation (manifest checked, complete views only)."""
    from scenegen.dataset import Dataset, DatasetError

    p = Path(path)
    if not is_dataset(p):
        raise InputError(f"{p}: not a scenegen dataset (expected a directory with manifest.json and cameras.json)")
    try:
        ds = Dataset(p)
        views = tuple(ds.views)
    except DatasetError as exc:
        raise InputError(str(exc)) from None
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{p / 'cameras.json'}: unreadable ({type(exc).__name__}: {exc})") from None
    if not views:
        raise InputError(f"{p / 'manifest.json'}: views: no complete view in this dataset")
    return DatasetTruth(p, views, ds)
