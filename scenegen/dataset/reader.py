"""Reading a dataset: typed access to everything it holds, through :mod:`.layout` and the codecs.

    >>> d = Dataset("out/demo")                    # doctest: +SKIP
    >>> len(d), d.views[0]                         # complete views, in the run's order
    >>> camera, cam_from_world = d.camera(d.views[0])
    >>> truth = d.truth(d.views[0])                # depth_z, range, points_world, ..., valid
    >>> d.crossview.correspondence("a", "b")       # dense correspondences with visibility
    >>> d.crossview.stereo("left_0000").disparity("left")
    >>> d.streams["imu0"].field("gyro_rad_s")       # a sensor's samples beside the views

Needs numpy, OpenCV and OpenEXR (trimesh for meshes); never Mitsuba. File hashes are not
checked here: :func:`scenegen.dataset.verify.verify` does that. A missing view raises KeyError, a
missing or unreadable file :class:`~scenegen.dataset.errors.DatasetError` naming it.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from scenegen.dataset.boxes import ViewBoxes, decode_boxes
from scenegen.dataset.cameras import camera_of
from scenegen.dataset.codecs.dng import read_dng
from scenegen.dataset.codecs.exr import read_exr, unpack_channels
from scenegen.dataset.codecs.json import read_json
from scenegen.dataset.codecs.ply import read_ply
from scenegen.dataset.codecs.png import read_png
from scenegen.dataset.crossview_reader import CrossviewTruth
from scenegen.dataset.errors import DatasetError
from scenegen.dataset.layout import (
    CAMERAS,
    MESHES_DIR,
    TARGETS_DIR,
    VIGNETTING_CHANNEL,
    COC_CHANNEL,
    albedo_path,
    boxes_path,
    check_listed_names,
    coc_path,
    check_rel_path,
    mesh_path,
    names_under,
    lights_path,
    pattern_sequence_path,
    projector_truth_path,
    target_path,
    view_paths,
    vignetting_path,
)
from scenegen.dataset.journal import load_current_manifest
from scenegen.dataset.manifest import STATUS_COMPLETE
from scenegen.dataset.photometric import ViewLight, decode_albedo, decode_lights
from scenegen.dataset.raw import RawImage, raw_image
from scenegen.dataset.sequence_reader import SequenceTruth
from scenegen.dataset.stream_reader import Streams
from scenegen.dataset.structured_light import ProjectorTruth, decode_pattern_sequence, decode_projector_truth
from scenegen.dataset.truth import LINEAR_CHANNELS, TRUTH_FLOAT_CHANNELS, TruthKind, decode_truth
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3


class Dataset:
    """Read-only access to a dataset directory.

    ``views`` lists the complete views in the run's order (cameras.json), ``all_views`` every
    declared view; ``len(d)`` is the number of complete views.
    """

    def __init__(self, out_dir):
        self.root = Path(out_dir)
        self.manifest: dict = load_current_manifest(self.root)  # with an unfinished run's journal
        _check_names(f"{self.root / 'manifest.json'}", views=self.manifest["views"],
                     paths=list(self.manifest["files"])
                     + [r for e in self.manifest["views"].values() for r in e.get("files", ())])
        self._cameras: dict | None = None
        self._crossview: CrossviewTruth | None = None

    def __repr__(self) -> str:
        return (f"Dataset({str(self.root)!r}: {len(self.views)} of {len(self.all_views)} views complete,"
                f" {len(self.manifest['files'])} files, variant {self.manifest['variant']})")

    def __len__(self) -> int:
        return len(self.views)

    def __contains__(self, view: str) -> bool:
        return view in self.views

    # --- files
    def path(self, rel_path: str) -> Path:
        """The absolute path of a file of the dataset (``rel_path`` checked: no '..', no hidden)."""
        return self.root / check_rel_path(rel_path)

    def has(self, rel_path: str) -> bool:
        """True if the manifest lists ``rel_path``."""
        return rel_path in self.manifest["files"]

    def _file(self, rel_path: str, what: str) -> Path:
        """The path of a file the manifest lists; DatasetError saying what is missing otherwise."""
        p = self.path(rel_path)
        if not self.has(rel_path) or not p.is_file():
            raise DatasetError(f"{p}: no such file in this dataset ({what})")
        return p

    def read(self, rel_path: str, reader, what: str):
        """``reader(path)`` of a listed file; its ValueError/KeyError becomes a DatasetError."""
        p = self._file(rel_path, what)
        try:
            return reader(p)
        except (ValueError, KeyError, OSError) as e:  # the codecs name the file too: name it once
            detail = str(e).removeprefix(f"{p}: ")
            raise DatasetError(f"{p}: unreadable {what}: {detail}") from None

    # --- views and cameras
    @property
    def cameras(self) -> dict:
        """The parsed cameras.json (empty views if the run wrote none)."""
        if self._cameras is None:
            p = self.root / CAMERAS
            doc = read_json(p) if p.is_file() else {"view_order": [], "views": {}, "spec": None}
            if not (isinstance(doc, dict) and isinstance(doc.get("view_order"), list)
                    and isinstance(doc.get("views"), dict)):
                raise DatasetError(f"{p}: expected a JSON object with 'view_order' (a list) and 'views'")
            infos = [e for e in doc["views"].values() if isinstance(e, dict)]
            _check_names(str(p), views=list(doc["view_order"]) + list(doc["views"]),
                         names=[(what, e[k]) for e in infos for k, what in
                                (("camera_name", "camera"), ("rig", "rig"), ("rig_member", "rig member"))
                                if e.get(k) is not None])
            self._cameras = doc
        return self._cameras

    @property
    def all_views(self) -> tuple[str, ...]:
        order = list(self.cameras["view_order"])
        return tuple(order + sorted(set(self.manifest["views"]) - set(order)))

    @property
    def views(self) -> tuple[str, ...]:
        status = self.manifest["views"]
        return tuple(v for v in self.all_views if status.get(v, {}).get("status") == STATUS_COMPLETE)

    @property
    def spec(self) -> dict | None:
        """The resolved scene spec the run used (from cameras.json)."""
        return self.cameras["spec"]

    @property
    def scene_name(self) -> str:
        """The spec's scene name, else the folder's name."""
        return str((self.spec or {}).get("name") or self.root.name)

    @property
    def objects(self) -> list[dict]:
        """The spec's objects (resolved dicts, spec order; object ``k`` has object_id ``k + 1``)."""
        return list((self.spec or {}).get("objects", []))

    def object_id(self, name: str) -> int:
        """The object id (>= 1) of the spec object ``name`` (KeyError if there is none)."""
        names = [o.get("name") for o in self.objects]
        if name not in names:
            raise KeyError(f"no object {name!r} in this dataset's spec (objects: {', '.join(map(str, names))})")
        return names.index(name) + 1

    def check_view(self, view: str) -> str:
        """``view`` if it is complete; KeyError saying what it is otherwise."""
        e = self.manifest["views"].get(view)
        if e is None or e["status"] != STATUS_COMPLETE:
            state = "not in this dataset" if e is None else f"{e['status']}, not complete"
            raise KeyError(f"view {view!r} is {state}")
        return view

    def view_info(self, view: str) -> dict:
        """The view's raw cameras.json entry (camera dict, cam_from_world, rig membership)."""
        try:
            return self.cameras["views"][view]
        except KeyError:
            raise KeyError(f"view {view!r} is not in {CAMERAS}") from None

    def camera(self, view: str) -> tuple[Camera, Rigid3]:
        """``(Camera, cam_from_world)`` of a view."""
        return camera_of(self.view_info(view))

    def views_of_camera(self, camera_name: str) -> tuple[str, ...]:
        """Complete views taken with the spec camera ``camera_name``, in view order."""
        return tuple(v for v in self.views if self.view_info(v).get("camera_name") == camera_name)

    def rig_partners(self, view: str) -> tuple[str, ...]:
        """The other complete views of ``view``'s rig at the same frame (empty for a free camera)."""
        info = self.view_info(view)
        if info.get("rig") is None:
            return ()
        return tuple(v for v in self.views if v != view and self.view_info(v).get("rig") == info["rig"]
                     and self.view_info(v).get("frame_index") == info.get("frame_index"))

    # --- per-view files
    def _view_file(self, view: str, key: str) -> str:
        return view_paths(self.check_view(view))[key]

    def image(self, view: str) -> np.ndarray:
        """The rendered image: (H, W, 3) RGB or (H, W) grey, uint8 or uint16."""
        return self.read(self._view_file(view, "image"), read_png, f"image of view {view!r}")

    def image_path(self, view: str) -> Path:
        """The rendered image's file (images/<view>.png), for tools that read files."""
        return self.path(self._view_file(view, "image"))

    def linear_image(self, view: str) -> np.ndarray:
        """Clean linear radiance, (H, W, 3) float32 RGB."""
        ch = self.read(self._view_file(view, "linear"), read_exr, f"linear image of view {view!r}")
        return unpack_channels(ch, "", LINEAR_CHANNELS)

    def truth_channels(self, view: str) -> dict[str, np.ndarray]:
        """The float truth EXR of a view, channel name -> (H, W) float32 (no ids, no mask)."""
        return self.read(self._view_file(view, "truth"), read_exr, f"truth of view {view!r}")

    def truth(self, view: str) -> dict[str, np.ndarray]:
        """Per-pixel truth of the ray through each pixel centre (keys
        :data:`scenegen.dataset.truth.TRUTH_KEYS`): depth_z, range (H, W) float32 metres (+inf on
        misses); points_world, points_cam, normals_world, normals_cam (H, W, 3) float32 (NaN on
        misses); uv (H, W, 2) float32; object_id, instance_id (H, W) uint32 (0 = none); valid
        (H, W) bool."""
        what = f"truth of view {view!r}"
        ids = self.read(self._view_file(view, "ids"), read_exr, what)
        valid = self.read(self._view_file(view, "valid"), read_png, what)
        try:
            return decode_truth(self.truth_channels(view), ids, valid)
        except KeyError as e:
            raise DatasetError(f"{self.path(self._view_file(view, 'truth'))}: {e.args[0]}") from None

    def depth_z(self, view: str) -> np.ndarray:
        """(H, W) float32 z-depth, metres; +inf where the ray hit nothing."""
        return self._truth_channel(view, TruthKind.DEPTH_Z)

    def points_world(self, view: str) -> np.ndarray:
        """(H, W, 3) float32 world points, metres; NaN where the ray hit nothing."""
        return self._truth_channel(view, TruthKind.POINTS_WORLD)

    def object_ids(self, view: str) -> np.ndarray:
        """(H, W) uint32 object id of each pixel centre's hit (spec object k is k + 1; 0 = none)."""
        return self.read(self._view_file(view, "ids"), lambda p: read_exr(p)[TruthKind.OBJECT_ID],
                         f"object ids of view {view!r}")

    def _truth_channel(self, view: str, key: str) -> np.ndarray:
        prefix, comps = TRUTH_FLOAT_CHANNELS[key]
        ch = self.truth_channels(view)
        try:
            return ch[prefix] if comps is None else unpack_channels(ch, prefix, comps)
        except KeyError as e:
            raise DatasetError(f"{self.path(self._view_file(view, 'truth'))}: no channel(s) for {key} ({e})") from None

    def vignetting(self, view: str) -> np.ndarray | None:
        """(H, W) float32 vignetting map of the imaging chain, or None if the camera has none."""
        rel = vignetting_path(self.check_view(view))
        return read_exr(self.path(rel))[VIGNETTING_CHANNEL] if self.has(rel) else None

    def albedo(self, view: str) -> np.ndarray | None:
        """(H, W, 3) float32 diffuse albedo per pixel centre (NaN on misses), or None when the
        spec did not ask for it (``truth: {albedo: true}``)."""
        rel = albedo_path(self.check_view(view))
        return self.read(rel, lambda p: decode_albedo(read_exr(p)), f"albedo of view {view!r}") \
            if self.has(rel) else None

    def coc_radius_px(self, view: str) -> np.ndarray | None:
        """(H, W) float32 thin-lens circle-of-confusion radius (px) of each pixel's truth point
        (NaN on misses), or None when the spec did not ask for it (``truth: {defocus: true}``)."""
        rel = coc_path(self.check_view(view))
        return self.read(rel, read_exr, f"circle of confusion of view {view!r}")[COC_CHANNEL] if self.has(rel) else None

    def lights(self, view: str) -> tuple[ViewLight, ...] | None:
        """The lights on in a view, in its camera frame (:class:`scenegen.dataset.photometric.ViewLight`),
        or None when the spec did not ask for them (``truth: {lights: true}``)."""
        rel = lights_path(self.check_view(view))
        return self.read(rel, lambda p: decode_lights(read_json(p), str(p)), f"lights of view {view!r}") \
            if self.has(rel) else None

    def boxes(self, view: str) -> ViewBoxes | None:
        """Every object's visible and amodal 2D boxes and 3D box in a view
        (:class:`scenegen.dataset.boxes.ViewBoxes`), or None when the spec did not ask for them
        (``truth: {boxes: true}``)."""
        rel = boxes_path(self.check_view(view))
        return self.read(rel, lambda p: decode_boxes(read_json(p), str(p)), f"boxes of view {view!r}") \
            if self.has(rel) else None

    def projector_truth(self, view: str) -> ProjectorTruth | None:
        """A projector-lit view's per-pixel projector truth (:class:`scenegen.dataset.structured_light
        .ProjectorTruth`: projector pixel, lit mask, column/row and Gray codes), or None for a view
        no projector lights."""
        rel = projector_truth_path(self.check_view(view))
        return self.read(rel, lambda p: decode_projector_truth(p.read_bytes()), f"projector truth of view {view!r}") \
            if self.has(rel) else None

    def pattern_sequence(self, view: str) -> dict | None:
        """A projector-lit view's ``patterns/<view>/sequence.json`` (the projector's camera and pose,
        radiometry, and each pattern with its image file), or None for a view no projector lights."""
        rel = pattern_sequence_path(self.check_view(view))
        return self.read(rel, lambda p: decode_pattern_sequence(read_json(p), str(p)),
                         f"pattern sequence of view {view!r}") if self.has(rel) else None

    def pattern_images(self, view: str) -> np.ndarray:
        """(N, H, W[, 3]) the view's images under its projector's N patterns, in order."""
        doc = self.pattern_sequence(view)
        if doc is None:
            raise DatasetError(f"view {view!r} is not lit by a projector (no {pattern_sequence_path(view)})")
        return np.stack([self.read(check_rel_path(e["image"]), read_png, f"pattern {e.get('index')} of view {view!r}")
                         for e in doc["patterns"]])

    def raw(self, view: str, kind: str | None = None) -> RawImage | None:
        """The raw mosaic of a view (:class:`scenegen.dataset.raw.RawImage`: uint16 DN, CFA,
        black and white levels, colour data, the recorded ISP stages), or None if its camera
        wrote none. ``kind``: ``'dng'`` or ``'png'``; default the DNG when written."""
        record = self.view_info(self.check_view(view)).get("raw")
        if record is None:
            return None
        files = record["files"]
        kind = kind or ("dng" if "dng" in files else "png")
        if kind not in files:
            raise DatasetError(f"view {view!r} has no raw {kind} file (written: {', '.join(files)})")
        rel, what = files[kind], f"raw mosaic of view {view!r}"
        if kind == "dng":
            dng = self.read(rel, read_dng, what)
            return raw_image(dng.mosaic, record, rel, dng)
        return raw_image(self.read(rel, read_png, what), record, rel)

    # --- the scene
    @property
    def mesh_names(self) -> tuple[str, ...]:
        return names_under(self.manifest["files"], MESHES_DIR, ".ply")

    @property
    def target_names(self) -> tuple[str, ...]:
        """Objects that are calibration targets (with points in scene/targets/)."""
        return names_under(self.manifest["files"], TARGETS_DIR, ".json")

    def mesh(self, name: str):
        """A world-frame mesh as a trimesh.Trimesh."""
        return self.read(mesh_path(name), read_ply, f"mesh of object {name!r}")

    def target(self, name: str) -> dict:
        """A calibration target's points: kind, point_ids, points_board, points_world (metres),
        world_from_board, marker ids and corners for ChArUco/ArUco boards."""
        return self.read(target_path(name), read_json, f"points of target {name!r}")

    # --- cross-view truth
    @property
    def crossview(self) -> CrossviewTruth:
        """The cross-view truth (docs/crossview.md); ``crossview.index`` is None without any."""
        if self._crossview is None:
            self._crossview = CrossviewTruth(self)
        return self._crossview

    # --- sequence truth
    @property
    def sequence(self) -> SequenceTruth:
        """The truth across time of a sequence (docs/crossview.md, "Sequences")."""
        return SequenceTruth(self)

    # --- streams beside the views
    @property
    def streams(self) -> Streams:
        """The sensors' streams (IMU samples, LiDAR beams, ...; docs/dataset_format.md, "Streams")."""
        return Streams(self)


def _check_names(source: str, *, views=(), paths=(), names=()) -> None:
    """Every name a dataset file lists is checked once, when the file is read (DatasetError)."""
    try:
        check_listed_names(source, views=views, paths=paths, names=names)
    except ValueError as e:
        raise DatasetError(str(e)) from None
