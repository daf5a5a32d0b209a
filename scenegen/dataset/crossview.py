"""The cross-view truth as stored: correspondence states, the correspondence and match-set codecs,
and the typed ``crossview/index.json`` (docs/crossview.md).

* Correspondence state of each pixel of view i in view j (:data:`STATE_NAMES`): ``NO_SURFACE``
  (0, pixel i saw nothing), ``VISIBLE`` (1, P projects inside j's image and j sees P, decided by a
  ray cast), ``OCCLUDED`` (2, another surface is hit first, or a board seen from its back),
  ``OUT_OF_FRAME`` (3, outside j's image, behind j, or beyond j's model's valid field of view).
  The one visibility truth of the project: the evaluator reads these states, never re-derives them.
* ``crossview/corr/<i>/<j>.exr``: channels ``u``, ``v`` (FLOAT, OpenCV pixels of j), ``z`` (FLOAT,
  metres along j's optical axis), ``state`` (UINT).
* Match sets ``crossview/matches/<i>/<j>_<kind>.npy``: (N, 8) float64 rows, :data:`MATCH_COLUMNS`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from scenegen.dataset.layout import check_listed_names

NO_SURFACE, VISIBLE, OCCLUDED, OUT_OF_FRAME = 0, 1, 2, 3
STATE_NAMES = {NO_SURFACE: "no_surface", VISIBLE: "visible", OCCLUDED: "occluded", OUT_OF_FRAME: "out_of_frame"}

#: A point P seen from a camera centre C is VISIBLE when the first hit along the ray C -> P is
#: no nearer than |P - C| (1 - OCCLUSION_REL_TOL). Why 1e-4: P itself comes from a float32
#: intersection (relative error ~1e-7 of its distance) and the re-intersection from C is float32
#: too; at grazing incidence the along-ray error grows by 1 / cos(angle), ~60x at 89 degrees, so
#: a few 1e-6 relative. 1e-4 leaves a 10x margin there while any occluder farther than 0.01 % of
#: the distance in front of P (0.3 mm at 3 m) still occludes. Implemented by
#: :func:`scenegen.render.raycast.visible_from`; tested in tests/scenegen/pipeline/test_crossview_truth.py.
OCCLUSION_REL_TOL = 1e-4

MATCH_COLUMNS = ("u_i", "v_i", "u_j", "v_j", "u_j_true", "v_j_true", "label", "error_px")
INLIER, UNIFORM_OUTLIER, NEAR_MISS_OUTLIER, WRONG, NO_TRUTH = 0, 1, 2, 3, 4
LABELS = {INLIER: "inlier", UNIFORM_OUTLIER: "uniform_outlier", NEAR_MISS_OUTLIER: "near_miss_outlier",
          WRONG: "wrong (real match farther than the inlier threshold from the truth)",
          NO_TRUTH: "no_truth (the point is not visible in j: occluded, out of frame or no surface)"}

INDEX_FORMAT = "scenegen-crossview"
INDEX_FORMAT_VERSION = 1
#: Flags of a pair's "pixels" field in twoview JSON: what F, E and H apply to.
TWOVIEW_PIXELS = "undistorted OpenCV pixels: x = K (X/Z, Y/Z, 1); x_j^T F x_i = 0"


@dataclass(frozen=True, eq=False)
class Correspondence:
    """Dense correspondence field of view i in view j, arrays over i's pixels (H_i, W_i)."""

    uv: np.ndarray  # (H, W, 2) float64 pixels of j (NaN where there is no surface or no projection)
    z: np.ndarray  # (H, W) float64 depth (z along j's optical axis) of P in j's frame, metres (NaN: none)
    state: np.ndarray  # (H, W) uint8, NO_SURFACE / VISIBLE / OCCLUDED / OUT_OF_FRAME

    @property
    def visible(self) -> np.ndarray:
        """(H, W) bool: pixels of i that j sees."""
        return self.state == VISIBLE

    @property
    def shape(self) -> tuple[int, int]:
        return self.state.shape

    def __len__(self) -> int:
        return int(self.state.size)

    def __repr__(self) -> str:
        counts = {STATE_NAMES[k]: int(np.count_nonzero(self.state == k)) for k in STATE_NAMES}
        return f"Correspondence({self.shape[1]}x{self.shape[0]}, {counts})"


def encode_correspondence_channels(c: Correspondence) -> dict[str, np.ndarray]:
    """EXR channels ``u``, ``v``, ``z`` (float32) and ``state`` (uint32) of a correspondence."""
    return {"u": c.uv[..., 0].astype(np.float32), "v": c.uv[..., 1].astype(np.float32),
            "z": c.z.astype(np.float32), "state": c.state.astype(np.uint32)}


def decode_correspondence_channels(channels: Mapping[str, np.ndarray]) -> Correspondence:
    """Inverse of :func:`encode_correspondence_channels` (float32 u, v, z widened exactly);
    KeyError naming a missing channel."""
    missing = [k for k in ("u", "v", "z", "state") if k not in channels]
    if missing:
        raise KeyError(f"correspondence channels {missing} missing; have {sorted(channels)}")
    uv = np.stack([channels["u"], channels["v"]], -1).astype(np.float64)
    return Correspondence(uv, np.asarray(channels["z"], np.float64), np.asarray(channels["state"]).astype(np.uint8))


#: EXR channels of a rectification map (map_x, map_y: the raw pixel of each rectified pixel).
#: Named R and G because OpenCV's EXR reader knows no other names: ``cv2.imread(path,
#: cv2.IMREAD_UNCHANGED)`` (with OPENCV_IO_ENABLE_OPENEXR=1) gives BGR = (0, map_y, map_x).
RECTIFICATION_MAP_CHANNELS = ("R", "G")
#: The names written before the maps became OpenCV-readable (still read).
_OLD_MAP_CHANNELS = ("map_x", "map_y")


def encode_rectification_map(map_xy) -> dict[str, np.ndarray]:
    """EXR channels of an (H, W, 2) map (x, y raw pixels), float32 R = map_x, G = map_y."""
    m = np.asarray(map_xy)
    return {name: m[..., k].astype(np.float32) for k, name in enumerate(RECTIFICATION_MAP_CHANNELS)}


def decode_rectification_map(channels: Mapping[str, np.ndarray]) -> np.ndarray:
    """(H, W, 2) float32 map of :func:`encode_rectification_map`'s channels (or the older
    ``map_x``, ``map_y``); KeyError naming what is missing."""
    for names in (RECTIFICATION_MAP_CHANNELS, _OLD_MAP_CHANNELS):
        if all(n in channels for n in names):
            return np.stack([np.asarray(channels[n], np.float32) for n in names], axis=-1)
    raise KeyError(f"rectification map channels {RECTIFICATION_MAP_CHANNELS} missing; have {sorted(channels)}")


@dataclass(frozen=True, eq=False)
class MatchSet:
    """Labelled putative matches of a pair: ``rows`` (N, 8) float64 in :data:`MATCH_COLUMNS` order."""

    i: str
    j: str
    kind: str  # 'synthetic' or 'sift'
    rows: np.ndarray

    def column(self, name: str) -> np.ndarray:
        """(N,) one column by name (:data:`MATCH_COLUMNS`)."""
        return self.rows[:, MATCH_COLUMNS.index(name)]

    @property
    def points_i(self) -> np.ndarray:
        """(N, 2) observed pixels of view i."""
        return self.rows[:, 0:2]

    @property
    def points_j(self) -> np.ndarray:
        """(N, 2) observed pixels of view j."""
        return self.rows[:, 2:4]

    @property
    def truth_j(self) -> np.ndarray:
        """(N, 2) the exact correspondence in j of the true point of i."""
        return self.rows[:, 4:6]

    @property
    def labels(self) -> np.ndarray:
        """(N,) int labels (:data:`LABELS`)."""
        return self.column("label").astype(np.int64)

    @property
    def inliers(self) -> np.ndarray:
        """(N,) bool: labelled inliers."""
        return self.column("label") == INLIER

    def __len__(self) -> int:
        return len(self.rows)

    def __repr__(self) -> str:
        n_in = int(self.inliers.sum())
        return f"MatchSet({self.i!r} -> {self.j!r}, {self.kind}, {len(self)} matches, {n_in} inliers)"


def check_match_rows(rows) -> np.ndarray:
    """``rows`` as (N, 8) float64; ValueError otherwise."""
    a = np.asarray(rows, np.float64)
    if a.ndim != 2 or a.shape[1] != len(MATCH_COLUMNS):
        raise ValueError(f"match rows must be (N, {len(MATCH_COLUMNS)}) {MATCH_COLUMNS}, got {a.shape}")
    return a


@dataclass(frozen=True)
class CrossviewIndex:
    """``crossview/index.json``: what cross-view truth a run wrote.

    ``pairs``: [(i, j)] with dense correspondences both ways and two-view geometry, in order;
    ``flow``: [(i, j)] with flow both ways; ``stereo``: [(left, right)] rectified frames;
    ``targets``: views with per-view board truth; ``pair_info``: each pair's raw entry (match-set
    counts and seeds); ``occlusion_rel_tol``: the visibility tolerance of the ray casts.
    """

    pairs: tuple[tuple[str, str], ...]
    flow: tuple[tuple[str, str], ...]
    stereo: tuple[tuple[str, str], ...]
    targets: tuple[str, ...]
    occlusion_rel_tol: float
    pair_info: tuple[dict, ...]
    files: tuple[str, ...]

    @classmethod
    def from_dict(cls, d: Mapping) -> "CrossviewIndex":
        """From the parsed JSON; ValueError naming the field that is not as written by scenegen."""
        if not isinstance(d, Mapping):
            raise ValueError(f"expected a JSON object, got {type(d).__name__}")
        if d.get("format") != INDEX_FORMAT or d.get("format_version") != INDEX_FORMAT_VERSION:
            raise ValueError(f"format: expected {INDEX_FORMAT!r} version {INDEX_FORMAT_VERSION}, got"
                             f" {d.get('format')!r} version {d.get('format_version')!r}")

        def pairs_of(key, a, b):
            items = d.get(key)
            if not isinstance(items, list) or not all(isinstance(e, Mapping) and isinstance(e.get(a), str)
                                                      and isinstance(e.get(b), str) for e in items):
                raise ValueError(f"{key}: expected a list of {{{a!r}: view, {b!r}: view}} entries")
            return tuple((e[a], e[b]) for e in items)

        targets = d.get("targets")
        if not isinstance(targets, list) or not all(isinstance(v, str) for v in targets):
            raise ValueError("targets: expected a list of view names")
        pairs, flow = pairs_of("pairs", "i", "j"), pairs_of("flow", "i", "j")
        stereo, files = pairs_of("stereo", "left_view", "right_view"), d.get("files", [])
        if not isinstance(files, (list, tuple)) or not all(isinstance(r, str) for r in files):
            raise ValueError("files: expected a list of relative paths")
        check_listed_names("index", views=[v for p in pairs + flow + stereo for v in p] + targets,
                           paths=files)  # names become paths: checked before any is used
        return cls(pairs=pairs, flow=flow, stereo=stereo, targets=tuple(targets),
                   occlusion_rel_tol=float(d.get("occlusion_rel_tol", float("nan"))),
                   pair_info=tuple(dict(e) for e in d["pairs"]), files=tuple(files))

    def __len__(self) -> int:
        return len(self.pairs)

    def __repr__(self) -> str:
        return (f"CrossviewIndex({len(self.pairs)} pairs, {len(self.flow)} flow pairs, {len(self.stereo)} stereo"
                f" frames, {len(self.targets)} target views)")
