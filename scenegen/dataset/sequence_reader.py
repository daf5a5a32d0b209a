"""Typed access to a dataset's sequence truth (docs/crossview.md, "Sequences"): the index, every
object's pose per frame, the motion truth of a frame pair (flow, scene flow, occlusion state),
a stereo rig's motion truth on the rectified grid (KITTI scene flow) and the point tracks of a
stream. Reached as ``Dataset(path).sequence``."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.dataset.codecs import TrackSet, decode_flo, read_exr, read_json, read_tracks
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.layout import (
    SEQUENCE_INDEX,
    check_listed_names,
    SEQUENCE_OBJECTS,
    motion_path,
    sequence_flow_path,
    stereo_motion_path,
    tracks_path,
)
from scenegen.dataset.sequence import (
    SEQUENCE_FORMAT,
    SEQUENCE_FORMAT_VERSION,
    MotionTruth,
    StereoMotionTruth,
    decode_motion_channels,
    decode_stereo_motion_channels,
)
from scenegen.geometry.pose import Rigid3


@dataclass(frozen=True)
class SequenceIndex:
    timestamps_s: tuple[float, ...]
    pairs: tuple[tuple[str, str, int], ...]  # (a, b, step): motion truth a -> b and b -> a
    streams: dict  # stream name -> its frames (view names, in order)
    stereo_pairs: tuple[tuple[str, str, int], ...] = ()  # (left a, left b, step): stereo motion both ways

    @classmethod
    def from_dict(cls, d) -> SequenceIndex:
        if d.get("format") != SEQUENCE_FORMAT or d.get("format_version") != SEQUENCE_FORMAT_VERSION:
            raise ValueError(f"format: expected {SEQUENCE_FORMAT!r} version {SEQUENCE_FORMAT_VERSION}, got "
                             f"{d.get('format')!r} version {d.get('format_version')!r}")
        return cls(tuple(float(t) for t in d["timestamps_s"]),
                   tuple((p["a"], p["b"], int(p["step"])) for p in d["pairs"]),
                   {t["stream"]: tuple(t["frames"]) for t in d["tracks"]},
                   tuple((p["a"], p["b"], int(p["step"])) for p in d.get("stereo_pairs", ())))

    def check_names(self, source: str) -> None:
        """Every view and stream name the index lists, checked before any reaches a path
        (:func:`scenegen.dataset.layout.check_listed_names`); ValueError naming ``source``."""
        views = [v for a, b, _ in self.pairs + self.stereo_pairs for v in (a, b)]
        views += [v for frames in self.streams.values() for v in frames]
        check_listed_names(source, views=views, names=[("stream", s) for s in self.streams])


class SequenceTruth:
    """The sequence truth of one dataset; ``index`` is None for a static scene."""

    def __init__(self, dataset):
        self._ds = dataset
        self._index = None

    @property
    def index(self) -> SequenceIndex | None:
        if self._index is None and self._ds.has(SEQUENCE_INDEX):
            doc = self._ds.read(SEQUENCE_INDEX, read_json, "sequence index")
            try:
                index = SequenceIndex.from_dict(doc)
            except (ValueError, KeyError, TypeError) as e:
                raise DatasetError(f"{self._ds.path(SEQUENCE_INDEX)}: {e}") from None
            try:  # once, where the index is read: every export and reader gets checked names
                index.check_names(str(self._ds.path(SEQUENCE_INDEX)))
            except ValueError as e:
                raise DatasetError(str(e)) from None
            self._index = index
        return self._index

    def object_poses(self, frame: int) -> dict[str, tuple[Rigid3, bool]]:
        """{object name: (world_from_object, present)} at a frame of the clock."""
        doc = self._ds.read(SEQUENCE_OBJECTS, read_json, "per-frame object poses")
        frames = doc["frames"]
        if not 0 <= frame < len(frames):
            raise DatasetError(f"frame {frame} is outside 0..{len(frames) - 1}")
        return {k: (Rigid3.from_dict(v["world_from_object"]), bool(v["present"]))
                for k, v in frames[frame]["objects"].items()}

    def moving_object_ids(self) -> set[int]:
        """Object ids whose pose or presence changes over the sequence's frames."""
        doc = self._ds.read(SEQUENCE_OBJECTS, read_json, "per-frame object poses")
        first = doc["frames"][0]["objects"]
        return {int(first[name]["object_id"]) for fr in doc["frames"][1:] for name, v in fr["objects"].items()
                if v["present"] != first[name]["present"] or v["world_from_object"] != first[name]["world_from_object"]}

    def motion(self, a: str, b: str) -> MotionTruth:
        """Where a's surface points are at b: correspondence (uv, z, state) and world scene flow."""
        return self._ds.read(motion_path(a, b), lambda p: decode_motion_channels(read_exr(p)),
                             f"motion truth {a} -> {b}")

    def flow(self, a: str, b: str) -> np.ndarray:
        """(H, W, 2) float32 optical flow a -> b (NaN unknown), from the .flo file."""
        return self._ds.read(sequence_flow_path(a, b), lambda p: decode_flo(p.read_bytes()), f"flow {a} -> {b}")

    def stereo_motion(self, a: str, b: str) -> StereoMotionTruth:
        """Where the rectified left surface points of stereo frame a (its left view) are in b's
        rectified pair: flow, depth, disparity f B / z and the states in both views."""
        return self._ds.read(stereo_motion_path(a, b), lambda p: decode_stereo_motion_channels(read_exr(p)),
                             f"stereo motion truth {a} -> {b} (a stereo rig with crossview.stereo in a sequence)")

    def tracks(self, stream: str) -> TrackSet:
        """The point tracks of a camera stream (:mod:`scenegen.dataset.codecs.tracks`)."""
        return self._ds.read(tracks_path(stream), read_tracks, f"tracks of stream {stream!r}")
