"""Reading a dataset's cross-view truth (docs/crossview.md): the index, dense correspondences with
their visibility, two-view geometry, match sets, flow, per-view board truth, rectified stereo.

Reached through :attr:`scenegen.dataset.reader.Dataset.crossview`. Every path comes from
:mod:`.layout` with checked view names, never from a string found in a file.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset.codecs.exr import read_exr
from scenegen.dataset.codecs.flo import decode_flo
from scenegen.dataset.codecs.json import read_json
from scenegen.dataset.codecs.kitti import decode_kitti_disparity
from scenegen.dataset.codecs.npy import read_npy
from scenegen.dataset.codecs.pfm import read_pfm
from scenegen.dataset.codecs.png import read_png
from scenegen.dataset.crossview import (
    Correspondence,
    CrossviewIndex,
    MatchSet,
    check_match_rows,
    decode_correspondence_channels,
    decode_rectification_map,
)
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.ir_stereo import decode_invalid
from scenegen.dataset.layout import (
    CAMERAS,
    CROSSVIEW_INDEX,
    STEREO_SIDES,
    correspondence_path,
    flow_path,
    matches_path,
    motion_path,
    stereo_path,
    twoview_path,
    view_targets_path,
)
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.twoview import fundamental

_NO_INDEX = "render the spec with a `crossview:` section (docs/scene_spec.md)"


@dataclass(frozen=True, eq=False)
class TwoViewTruth:
    """``crossview/twoview/<i>/<j>.json`` of a pair, typed (conventions: docs/crossview.md).

    ``F``, ``E`` and the epipoles are None for a zero baseline; F, E and H apply to UNDISTORTED
    OpenCV pixels ``x = K (X/Z, Y/Z, 1)``; ``homographies``: plane object name -> (3, 3) H."""

    i: str
    j: str
    j_from_i: Rigid3
    E: np.ndarray | None
    F: np.ndarray | None
    epipole_i: np.ndarray | None
    epipole_j: np.ndarray | None
    homographies: dict
    raw: dict  # the JSON as stored (plane normals and distances, epipoles in pixels)

    @property
    def baseline_m(self) -> float:
        return float(np.linalg.norm(self.j_from_i.t))

    @classmethod
    def from_dict(cls, d: dict) -> "TwoViewTruth":
        arr = lambda k: None if d.get(k) is None else np.asarray(d[k], np.float64)
        return cls(d["i"], d["j"], Rigid3.from_dict(d["j_from_i"]), arr("E"), arr("F"), arr("epipole_i"),
                   arr("epipole_j"), {k: np.asarray(h["H"], np.float64) for k, h in d.get("homographies", {}).items()},
                   d)

    def __repr__(self) -> str:
        return (f"TwoViewTruth({self.i!r} -> {self.j!r}, baseline {self.baseline_m:.4g} m,"
                f" {'F' if self.F is not None else 'no F (zero baseline)'}, planes {sorted(self.homographies)})")


class StereoFrame:
    """A rectified stereo frame ``crossview/stereo/<left view>/``: both sides rendered as the same
    ideal pinhole (``camera``), exact disparity ``d = u_left - u_right >= 0``."""

    def __init__(self, dataset, left_view: str, right_view: str):
        self._ds, self.left_view, self.right_view = dataset, left_view, right_view

    def __repr__(self) -> str:
        return f"StereoFrame({self.left_view!r}, {self.right_view!r}, baseline {self.baseline_m:.4g} m)"

    def _read(self, key: str, side: str | None, reader, what: str):
        if side is not None and side not in STEREO_SIDES:
            raise ValueError(f"side must be one of {STEREO_SIDES}, got {side!r}")
        return self._ds.read(stereo_path(self.left_view, key, side), reader,
                             f"rectified {what} of stereo frame {self.left_view!r}")

    @property
    def calib(self) -> dict:
        """calib.json: R1, R2, P1, P2, Q, the rectified camera, baseline, raw cameras and poses."""
        return self._read("calib", None, read_json, "calibration")

    @property
    def camera(self) -> Camera:
        """The rectified pinhole shared by both sides."""
        return Camera.from_dict(self.calib["camera"])

    @property
    def baseline_m(self) -> float:
        return float(self.calib["baseline_m"])

    def cam_from_world(self, side: str) -> Rigid3:
        return Rigid3.from_dict(self.calib[f"cam_{side}_from_world"])

    def image(self, side: str) -> np.ndarray:
        return self._read("image", side, read_png, "image")

    def disparity(self, side: str) -> np.ndarray:
        """(H, W) float32 disparity of one side (px), +inf where there is no surface."""
        return self._read("disparity_pfm", side, read_pfm, "disparity")

    def disparity_kitti(self, side: str, which: str) -> tuple[np.ndarray, np.ndarray]:
        """(disparity (H, W) float64, valid (H, W) bool) of the KITTI PNG: ``which`` = 'occ' (every
        pixel with a surface) or 'noc' (only those the other side sees)."""
        if which not in ("occ", "noc"):
            raise ValueError(f"which must be 'occ' or 'noc', got {which!r}")
        return self._read(f"disparity_{which}", side, lambda p: decode_kitti_disparity(p.read_bytes()),
                          f"KITTI {which} disparity")

    def correspondence(self, side: str) -> Correspondence:
        """Correspondences of one side in the other, with visibility."""
        return self._read("correspondence", side, lambda p: decode_correspondence_channels(read_exr(p)),
                          "correspondences")

    def rectification_map(self, side: str) -> np.ndarray:
        """(H, W, 2) float32 raw pixel of each rectified pixel (for cv2.remap)."""
        return self._read("map", side, lambda p: decode_rectification_map(read_exr(p)), "rectification map")

    def instance_ids(self, side: str) -> np.ndarray:
        """(H, W) uint32 instance id of the surface each rectified pixel centre sees (0 = none)."""
        return self._read("ids", side, read_exr, "ids")[TruthKind.INSTANCE_ID]

    def object_ids(self, side: str) -> np.ndarray:
        """(H, W) uint32 object id of the surface each rectified pixel centre sees (0 = none)."""
        return self._read("ids", side, read_exr, "ids")[TruthKind.OBJECT_ID]

    def ir_image(self, side: str, projector: bool = True) -> np.ndarray:
        """(H, W) monochrome IR image of one side (active IR stereo, a rig with a projector), the
        projector on or off (docs/dataset_format.md, "Active IR stereo")."""
        key = "ir" if projector else "ir_off"
        return self._read(key, side, read_png, f"IR image ({'projector on' if projector else 'projector off'})")

    def ir_invalid(self, side: str) -> np.ndarray:
        """(H, W) uint8 invalid bits of one side (:mod:`scenegen.dataset.ir_stereo`; 0 = valid)."""
        return self._read("ir_invalid", side, lambda p: decode_invalid(p.read_bytes()), "IR invalid mask")


class CrossviewTruth:
    """The cross-view truth of one dataset (see the module docstring)."""

    def __init__(self, dataset):
        self._ds = dataset
        self._index: CrossviewIndex | None = None
        self._has_index = dataset.has(CROSSVIEW_INDEX)

    def __repr__(self) -> str:
        return f"CrossviewTruth({self.index!r})" if self._has_index else "CrossviewTruth(none)"

    def __len__(self) -> int:
        return len(self.index) if self._has_index else 0

    @property
    def index(self) -> CrossviewIndex | None:
        """The typed crossview/index.json, or None when the run wrote no cross-view truth."""
        if self._index is None and self._has_index:
            doc = self._ds.read(CROSSVIEW_INDEX, read_json, "cross-view index")
            try:
                self._index = CrossviewIndex.from_dict(doc)
            except (ValueError, KeyError, TypeError) as e:
                raise DatasetError(f"{self._ds.path(CROSSVIEW_INDEX)}: {e}") from None
        return self._index

    def require_index(self) -> CrossviewIndex:
        """The index; DatasetError saying how to get one when there is none."""
        if self.index is None:
            raise DatasetError(f"{self._ds.root} has no cross-view truth ({CROSSVIEW_INDEX}); {_NO_INDEX}")
        return self.index

    @property
    def pairs(self) -> tuple[tuple[str, str], ...]:
        return self.index.pairs if self._has_index else ()

    def _views(self, i: str, j: str) -> None:
        self._ds.check_view(i)
        self._ds.check_view(j)

    def has_correspondence(self, i: str, j: str) -> bool:
        return self._ds.has(correspondence_path(i, j))

    def correspondence(self, i: str, j: str) -> Correspondence:
        """Dense correspondences of view i's pixels in view j with their ray-cast visibility."""
        self._views(i, j)
        return self._ds.read(correspondence_path(i, j), lambda p: decode_correspondence_channels(read_exr(p)),
                             f"correspondences {i!r} -> {j!r} (a pair of crossview.pairs)")

    def twoview(self, i: str, j: str) -> TwoViewTruth:
        """The two-view geometry of a pair (i, j) as written (i first)."""
        self._views(i, j)
        doc = self._ds.read(twoview_path(i, j), read_json, f"two-view geometry {i!r} -> {j!r}")
        try:
            return TwoViewTruth.from_dict(doc)
        except (KeyError, TypeError, ValueError) as e:
            raise DatasetError(f"{self._ds.path(twoview_path(i, j))}: {e}") from None

    def fundamental(self, i: str, j: str) -> tuple[np.ndarray | None, str]:
        """``(F (3, 3) or None, source)``: the truth F of i -> j for UNDISTORTED OpenCV pixels, the
        stored ``crossview/twoview/<i>/<j>.json`` when the dataset has it, else ``K2^-T [t]x R K1^-1``
        of cameras.json; None for a zero baseline (one camera centre)."""
        self._views(i, j)
        if self._ds.has(twoview_path(i, j)):
            return self.twoview(i, j).F, str(twoview_path(i, j))
        (c1, p1), (c2, p2) = self._ds.camera(i), self._ds.camera(j)
        rel = p2 @ p1.inverse()
        if np.linalg.norm(rel.t) == 0.0:
            return None, f"{CAMERAS}: one camera centre"
        return fundamental(c1.K, c2.K, rel), f"{CAMERAS}: K2^-T [t]x R K1^-1"

    def has_matches(self, i: str, j: str, kind: str) -> bool:
        return self._ds.has(matches_path(i, j, kind))

    def matches(self, i: str, j: str, kind: str) -> MatchSet:
        """The labelled match set ``kind`` ('synthetic' or 'sift') of a pair."""
        self._views(i, j)
        rows = self._ds.read(matches_path(i, j, kind), lambda p: check_match_rows(read_npy(p)),
                             f"{kind} matches {i!r} -> {j!r}")
        return MatchSet(i, j, kind, rows)

    def flow(self, i: str, j: str) -> np.ndarray:
        """(H, W, 2) float32 optical flow i -> j (px), NaN where unknown."""
        self._views(i, j)
        return self._ds.read(flow_path(i, j), lambda p: decode_flo(p.read_bytes()), f"flow {i!r} -> {j!r}")

    def pair_flow(self, i: str, j: str) -> tuple[np.ndarray, np.ndarray | None, str] | None:
        """The optical flow truth the dataset holds for views i -> j, ``(flow (H, W, 2) px,
        states (H, W) uint8 or None, source file)``, or None when it holds none: a sequence's motion
        truth of the pair (flow and occlusion states at j's time, moving objects too), else the flow
        file (consecutive frames), else the correspondence field ``uv - pixel`` of a crossview pair,
        with the states of the correspondence file when there is one. Non-finite where unknown."""
        self._views(i, j)
        if self._ds.has(motion_path(i, j)):
            m = self._ds.sequence.motion(i, j)
            return m.flow, m.state, str(motion_path(i, j))
        corr = self.correspondence(i, j) if self.has_correspondence(i, j) else None
        if self._ds.has(flow_path(i, j)):
            flow, source = self.flow(i, j), str(flow_path(i, j))
        elif corr is not None:
            H, W = corr.shape
            grid = np.stack(np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64)), -1)
            flow, source = corr.uv - grid, str(correspondence_path(i, j)) + " (uv - pixel)"
        else:
            return None
        return flow, None if corr is None else corr.state, source

    def view_targets(self, view: str) -> dict:
        """Per-view calibration-target truth: board name -> points' uv, depth, state, facing."""
        self._ds.check_view(view)
        return self._ds.read(view_targets_path(view), read_json, f"target truth of view {view!r}")["boards"]

    def stereo_frames(self) -> tuple[StereoFrame, ...]:
        """Every rectified stereo frame, in order."""
        idx = self.index
        return tuple(StereoFrame(self._ds, left, right) for left, right in (idx.stereo if idx is not None else ()))

    def stereo(self, left_view: str) -> StereoFrame:
        """The rectified frame whose left view is ``left_view`` (KeyError if there is none)."""
        for frame in self.stereo_frames():
            if frame.left_view == left_view:
                return frame
        raise KeyError(f"no rectified stereo frame with left view {left_view!r}")
