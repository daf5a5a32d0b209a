"""The dataset on disk: layout, writer (atomic, hashed, resumable), reader and ``verify``.

The format is documented for readers outside this project in ``docs/dataset_format.md``. In short::

    OUT/manifest.json                 format, spec hash, seed, variant, versions, view status, hashes
    OUT/cameras.json                  per view: camera, cam_from_world, rig membership; the spec
    OUT/scene/meshes/<name>.ply       meshes in the world frame
    OUT/images/<view>.png             rendered image, uint8 or uint16, RGB (or grey)
    OUT/images/<view>_linear.exr      clean linear float32 RGB: channels R, G, B
    OUT/truth/<view>.exr              float32 truth channels (depth_z, range, P_world.X, ...)
    OUT/truth/<view>_ids.exr          uint32 channels object_id, instance_id (0 = nothing)
    OUT/truth/<view>_valid.png        uint8 mask: 255 where the pixel centre's ray hit a surface

Crash safety: every file is written atomically (:mod:`scenegen.io`), and the manifest, rewritten
atomically after each completed view, lists a view as ``complete`` only after all of its files
are on disk, so a run killed at any point leaves a consistent dataset that ``resume=True`` can
finish. The manifest holds no timestamps or paths of the machine: the same spec, seed, variant and
software give byte-identical datasets, whatever the order in which views were written.

Nothing here imports Mitsuba or Dr.Jit; :meth:`Dataset.camera` imports :mod:`scenegen.camera`
lazily.
"""
from __future__ import annotations

import platform
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from scenegen import io as sio
from scenegen.pose import Rigid3

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "MANIFEST_NAME",
    "CAMERAS_NAME",
    "TRUTH_KEYS",
    "DatasetError",
    "DatasetMismatchError",
    "ViewCamera",
    "view_paths",
    "mesh_path",
    "check_truth",
    "encode_view",
    "write_view_files",
    "software_versions",
    "DatasetWriter",
    "Dataset",
    "VerifyReport",
    "verify",
]

FORMAT = "scenegen-dataset"
FORMAT_VERSION = 1
MANIFEST_NAME = "manifest.json"
CAMERAS_NAME = "cameras.json"

STATUS_COMPLETE = "complete"
STATUS_PENDING = "pending"

# View and mesh names become file names: keep them portable, and keep view names from colliding
# with another view's suffixed files (view "a_ids" would clash with view "a"'s truth/a_ids.exr).
_NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
_RESERVED_VIEW_SUFFIXES = ("_linear", "_ids", "_valid")
_MAX_NAME_LEN = 128

# Truth key -> (EXR channel prefix, component names); components None = a scalar channel.
_TRUTH_FLOAT_LAYOUT: dict[str, tuple[str, tuple[str, ...] | None]] = {
    "depth_z": ("depth_z", None),  # (H, W) metres along the optical axis
    "range": ("range", None),  # (H, W) metres from the optical centre
    "points_world": ("P_world", ("X", "Y", "Z")),  # (H, W, 3) metres, world frame
    "points_cam": ("P_cam", ("X", "Y", "Z")),  # (H, W, 3) metres, OpenCV camera frame
    "normals_world": ("N_world", ("X", "Y", "Z")),  # (H, W, 3) unit, world frame
    "normals_cam": ("N_cam", ("X", "Y", "Z")),  # (H, W, 3) unit, camera frame
    "uv": ("uv", ("U", "V")),  # (H, W, 2) texture coordinates
}
_TRUTH_ID_KEYS = ("object_id", "instance_id")  # (H, W) uint32, 0 = no object
#: Every key of a truth dict (writer input and reader output).
TRUTH_KEYS = tuple(_TRUTH_FLOAT_LAYOUT) + _TRUTH_ID_KEYS + ("valid",)
_UINT32_MAX = np.iinfo(np.uint32).max


class DatasetError(Exception):
    """A dataset directory is not what it should be (not a dataset, wrong format, bad name...)."""


class DatasetMismatchError(DatasetError):
    """Resuming, or re-writing a file, would mix outputs of different runs."""


# --- names and paths --------------------------------------------------------------------------
def _check_name(kind: str, name: str) -> str:
    if not isinstance(name, str) or not _NAME_RE.match(name) or len(name) > _MAX_NAME_LEN:
        raise ValueError(
            f"{kind} name {name!r} must be 1-{_MAX_NAME_LEN} characters from [A-Za-z0-9_.-],"
            " starting with a letter or digit")
    return name


def _check_view_name(view: str) -> str:
    _check_name("view", view)
    if view.endswith(_RESERVED_VIEW_SUFFIXES):
        raise ValueError(f"view name {view!r} must not end with {_RESERVED_VIEW_SUFFIXES}"
                         " (its files would collide with another view's)")
    return view


def view_paths(view: str) -> dict[str, str]:
    """Relative POSIX paths of a view's files: keys image, linear, truth, ids, valid."""
    _check_view_name(view)
    return {
        "image": f"images/{view}.png",
        "linear": f"images/{view}_linear.exr",
        "truth": f"truth/{view}.exr",
        "ids": f"truth/{view}_ids.exr",
        "valid": f"truth/{view}_valid.png",
    }


def mesh_path(name: str) -> str:
    """Relative POSIX path of a world-frame mesh."""
    return f"scene/meshes/{_check_name('mesh', name)}.ply"


def _check_rel_path(rel: str) -> str:
    """A relative POSIX path inside the dataset, not the manifest, no '..', no hidden parts."""
    if not isinstance(rel, str) or not rel or rel.startswith("/") or "\\" in rel:
        raise ValueError(f"dataset paths must be relative POSIX paths, got {rel!r}")
    parts = rel.split("/")
    if any(p in ("", ".", "..") or p.startswith(".") for p in parts):
        raise ValueError(f"dataset path {rel!r} has an empty, '.', '..' or hidden component")
    if rel == MANIFEST_NAME:
        raise ValueError(f"{MANIFEST_NAME} is written by the dataset writer only")
    return rel


# --- cameras ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class ViewCamera:
    """One view's entry in cameras.json.

    ``camera`` is a :class:`scenegen.camera.Camera` (anything with ``to_dict()``) or its dict;
    ``cam_from_world`` maps world points into the OpenCV camera frame (metres).
    """

    camera: Any
    cam_from_world: Rigid3
    camera_name: str  # the spec's camera this view was taken with
    rig: str | None = None  # rig name, None for a free camera
    rig_member: str | None = None  # member name inside the rig
    frame_index: int = 0  # index of the frame (rig pose) this view belongs to
    optics: Mapping[str, Any] | None = None  # lens, shutter, chromatic aberration, camera motion
    view_set: str | None = None  # prefix name of the spec view set the view belongs to
    lights: Mapping[str, float] | None = None  # every spec light -> factor on its spec power
    # used for this view (0 = off); None (older datasets) = not recorded

    def to_dict(self) -> dict:
        cam = self.camera.to_dict() if hasattr(self.camera, "to_dict") else dict(self.camera)
        pose = self.cam_from_world
        pose = pose.to_dict() if isinstance(pose, Rigid3) else Rigid3.from_dict(pose).to_dict()
        d = {"camera": cam, "cam_from_world": pose, "camera_name": self.camera_name,
             "rig": self.rig, "rig_member": self.rig_member, "frame_index": int(self.frame_index)}
        if self.view_set is not None:
            d["view_set"] = str(self.view_set)
        if self.lights is not None:
            d["lights"] = {str(k): float(v) for k, v in self.lights.items()}
        if self.optics:
            d["optics"] = dict(self.optics)
        return d


# --- truth ------------------------------------------------------------------------------------
def check_truth(truth: Mapping[str, np.ndarray], shape: tuple[int, int] | None = None) -> dict:
    """Validate a truth dict (keys :data:`TRUTH_KEYS`) and return it with arrays as stored.

    Float keys may be any float dtype; they are stored, and returned, as float32 (float64 input,
    e.g. from the truth pass, is rounded to nearest: about 6e-8 relative, far below 1e-3 px of
    reprojection error). ``object_id``/``instance_id``: integers in [0, 2^32) (returned as
    uint32); ``valid``: bool. Shapes: (H, W), (H, W, 3) for points and normals, (H, W, 2) for uv; ``shape`` (H, W)
    if given. Misses (``~valid``) must carry depth_z = range = +inf, NaN points, normals and uv,
    and ids 0; hits finite depth_z, range, points and normals.
    """
    missing = [k for k in TRUTH_KEYS if k not in truth]
    extra = [k for k in truth if k not in TRUTH_KEYS]
    if missing or extra:
        raise ValueError(f"truth keys: missing {missing}, unknown {extra}; expected {list(TRUTH_KEYS)}")
    valid = np.asarray(truth["valid"])
    if valid.dtype != np.bool_ or valid.ndim != 2:
        raise TypeError(f"truth 'valid' must be an (H, W) bool array, got {valid.dtype} {valid.shape}")
    hw = valid.shape
    if shape is not None and tuple(shape) != hw:
        raise ValueError(f"truth is {hw} (H, W) but the image is {tuple(shape)}")
    out: dict[str, np.ndarray] = {"valid": valid}
    miss = ~valid
    for key, (_, comps) in _TRUTH_FLOAT_LAYOUT.items():
        a = np.asarray(truth[key])
        want = hw if comps is None else hw + (len(comps),)
        if not np.issubdtype(a.dtype, np.floating):
            raise TypeError(f"truth {key!r} must be a float array (stored as float32), got {a.dtype}")
        if a.shape != want:
            raise ValueError(f"truth {key!r} must have shape {want}, got {a.shape}")
        a = a.astype(np.float32, copy=False)
        if key in ("depth_z", "range"):
            if not np.all(a[miss] == np.inf):
                raise ValueError(f"truth {key!r} must be +inf where valid is False")
        elif not np.all(np.isnan(a[miss])):
            raise ValueError(f"truth {key!r} must be NaN where valid is False")
        if key != "uv" and not np.all(np.isfinite(a[valid])):
            raise ValueError(f"truth {key!r} must be finite where valid is True")
        out[key] = a
    for key in _TRUTH_ID_KEYS:
        a = np.asarray(truth[key])
        if not np.issubdtype(a.dtype, np.integer) or a.shape != hw:
            raise TypeError(f"truth {key!r} must be an integer (H, W) = {hw} array, got {a.dtype} {a.shape}")
        if a.size and (a.min() < 0 or a.max() > _UINT32_MAX):
            raise ValueError(f"truth {key!r} values must lie in [0, 2^32 - 1]")
        a = a.astype(np.uint32, copy=False)
        if np.any(a[miss] != 0):
            raise ValueError(f"truth {key!r} must be 0 where valid is False")
        out[key] = a
    return out


def _truth_channels(truth: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    ch: dict[str, np.ndarray] = {}
    for key, (prefix, comps) in _TRUTH_FLOAT_LAYOUT.items():
        if comps is None:
            ch[prefix] = truth[key]
        else:
            ch.update(sio.pack_channels(prefix, truth[key], comps))
    return ch


# --- encoding and writing a view ----------------------------------------------------------------
def encode_view(view: str, *, image: np.ndarray, linear_rgb: np.ndarray,
                truth: Mapping[str, np.ndarray]) -> dict[str, bytes]:
    """Encode one view's files: ``{relative path: bytes}`` (pure; writes nothing).

    image: (H, W, 3) RGB or (H, W) grey, uint8 or uint16 (the rendered, possibly corrupted image).
    linear_rgb: (H, W, 3) float, clean linear radiance (stored as float32).
    truth: see :func:`check_truth`.
    """
    paths = view_paths(view)
    image = np.asarray(image)
    hw = image.shape[:2]
    linear_rgb = np.asarray(linear_rgb)
    if not np.issubdtype(linear_rgb.dtype, np.floating) or linear_rgb.shape != hw + (3,):
        raise ValueError(f"linear_rgb must be a float {hw + (3,)} array, got {linear_rgb.dtype}"
                         f" {linear_rgb.shape}")
    linear_rgb = linear_rgb.astype(np.float32, copy=False)
    t = check_truth(truth, shape=hw)
    return {
        paths["image"]: sio.encode_png(image),
        paths["linear"]: sio.encode_exr(sio.pack_channels("", linear_rgb, ("R", "G", "B"))),
        paths["truth"]: sio.encode_exr(_truth_channels(t)),
        paths["ids"]: sio.encode_exr({k: t[k] for k in _TRUTH_ID_KEYS}),
        paths["valid"]: sio.encode_png(np.where(t["valid"], np.uint8(255), np.uint8(0))),
    }


def _checked_extra_files(view: str, extra_files: Mapping[str, bytes] | None,
                         standard: Mapping[str, Any]) -> dict[str, bytes]:
    extra = {}
    for rel, data in (extra_files or {}).items():
        _check_rel_path(rel)
        if rel in standard or rel == CAMERAS_NAME:
            raise ValueError(f"extra file {rel!r} of view {view!r} collides with a standard file")
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise TypeError(f"extra file {rel!r}: pass encoded bytes (see scenegen.io.encode_*)")
        extra[rel] = bytes(data)
    return extra


def write_view_files(out_dir, view: str, *, image, linear_rgb, truth,
                     extra_files: Mapping[str, bytes] | None = None) -> dict[str, str]:
    """Write one view's files atomically under ``out_dir``; return ``{relative path: sha256}``.

    Does not touch the manifest: for a worker process, whose result the process owning the
    :class:`DatasetWriter` then records with :meth:`DatasetWriter.record_view`.
    ``extra_files`` maps further relative paths to encoded bytes, hashed and listed with the view.
    """
    files = encode_view(view, image=image, linear_rgb=linear_rgb, truth=truth)
    files.update(_checked_extra_files(view, extra_files, files))
    root = Path(out_dir)
    hashes = {}
    for rel, data in files.items():
        sio.atomic_write_bytes(root / rel, data)
        hashes[rel] = sio.sha256_bytes(data)
    return hashes


def software_versions() -> dict[str, str]:
    """Versions of the software that determine the output bytes (without importing Mitsuba)."""
    from importlib import metadata

    import cv2

    def dist_version(name: str) -> str:
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            return "not installed"

    return {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "opencv": cv2.__version__,
        "mitsuba": dist_version("mitsuba"),
        "drjit": dist_version("drjit"),
        "openexr": dist_version("OpenEXR"),
        "trimesh": dist_version("trimesh"),
        "scenegen": dist_version("scenegen"),
    }


# --- manifest ---------------------------------------------------------------------------------
_IDENTITY_KEYS = ("format", "format_version", "spec_sha256", "seed", "variant", "versions")
_MANIFEST_KEYS = _IDENTITY_KEYS + ("views", "files", "manifest_sha256")


def _manifest_bytes(body: Mapping[str, Any]) -> bytes:
    """Canonical manifest bytes: ``body`` plus ``manifest_sha256``, the SHA-256 of the canonical
    JSON of ``body`` itself (so a changed byte anywhere in manifest.json is detected)."""
    body = {k: v for k, v in body.items() if k != "manifest_sha256"}
    return sio.encode_json({**body, "manifest_sha256": sio.sha256_bytes(sio.encode_json(body))})


def _manifest_integrity_error(data: bytes) -> tuple[dict | None, str | None]:
    """Parse manifest bytes; return (manifest, None) or (None or manifest, reason it is corrupt)."""
    import json

    try:
        m = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        return None, f"not valid JSON ({e})"
    if not isinstance(m, dict) or set(m) != set(_MANIFEST_KEYS):
        keys = sorted(m) if isinstance(m, dict) else type(m).__name__
        return None, f"expected keys {sorted(_MANIFEST_KEYS)}, got {keys}"
    if _manifest_bytes(m) != data:
        return m, "content does not match its manifest_sha256 (or is not in canonical form)"
    return m, None


def _load_manifest(root: Path) -> dict:
    """Read and check manifest.json; raise DatasetError if absent, corrupt or of another format."""
    path = root / MANIFEST_NAME
    if not path.is_file():
        raise DatasetError(f"{root}: no {MANIFEST_NAME}; not a scenegen dataset")
    m, err = _manifest_integrity_error(path.read_bytes())
    if err:
        raise DatasetError(f"{path}: corrupted: {err}")
    if m["format"] != FORMAT:
        raise DatasetError(f"{path}: format is {m['format']!r}, expected {FORMAT!r}")
    if m["format_version"] != FORMAT_VERSION:
        raise DatasetError(f"{path}: format_version {m['format_version']!r} is not supported"
                           f" (this reader knows {FORMAT_VERSION})")
    return m


# --- writer -----------------------------------------------------------------------------------
class DatasetWriter:
    """Writes a dataset directory; owns its manifest (use one writer per directory).

    Typical use::

        w = DatasetWriter(out, spec_sha256=h, seed=s, variant=v, versions=software_versions(),
                          resume=args.resume)
        w.write_cameras(view_cameras, resolved_spec)     # declares every view (status pending)
        for name, mesh in world_meshes.items():
            w.write_mesh(name, mesh)
        for view in view_cameras:
            if w.is_complete(view):
                continue                                  # done by an earlier, interrupted run
            w.write_view(view, image=img, linear_rgb=lin, truth=truth)

    ``resume=False`` needs ``out_dir`` absent or empty. ``resume=True`` loads an existing manifest,
    which must have been written with the same spec_sha256, seed, variant, format and versions
    (else :class:`DatasetMismatchError`), removes temporary files left by a killed run, and keeps
    the completed views; a directory without a manifest is started afresh if it is empty.
    Re-writing a file that is already recorded with different content raises
    :class:`DatasetMismatchError` before anything is written: outputs must be deterministic.
    """

    def __init__(self, out_dir, *, spec_sha256: str, seed: int, variant: str,
                 versions: Mapping[str, str], resume: bool = False):
        self.root = Path(out_dir)
        if not (isinstance(spec_sha256, str) and re.fullmatch(r"[0-9a-f]{64}", spec_sha256)):
            raise ValueError(f"spec_sha256 must be 64 lower-case hex digits, got {spec_sha256!r}")
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
            raise TypeError(f"seed must be an int, got {seed!r}")
        identity = {
            "format": FORMAT, "format_version": FORMAT_VERSION, "spec_sha256": spec_sha256,
            "seed": int(seed), "variant": str(variant),
            "versions": {str(k): str(v) for k, v in versions.items()},
        }
        self._identity = identity
        self._views: dict[str, dict] = {}  # view -> {"status": ..., "files": [...]}
        self._files: dict[str, str] = {}  # relative path -> sha256
        self._view_order: list[str] = []

        has_manifest = (self.root / MANIFEST_NAME).is_file()
        if resume and self.root.is_dir():
            sio.remove_stale_temp_files(self.root)
        if resume and has_manifest:
            m = _load_manifest(self.root)
            diffs = [f"{k}: dataset has {m[k]!r}, this run has {identity[k]!r}"
                     for k in _IDENTITY_KEYS if m[k] != identity[k]]
            if diffs:
                raise DatasetMismatchError(
                    f"cannot resume {self.root}: it was written by a different run\n  "
                    + "\n  ".join(diffs) + "\nUse a new output directory.")
            self._views = {v: {"status": e["status"], "files": list(e["files"])}
                           for v, e in m["views"].items()}
            self._files = dict(m["files"])
        elif self.root.exists() and any(self.root.iterdir()):
            hint = "pass resume=True (--resume) to finish it" if has_manifest else "it has no manifest"
            raise DatasetError(f"{self.root} is not empty ({hint}); use a new or empty directory")
        self._write_manifest()

    # --- state
    def is_complete(self, view: str) -> bool:
        """True if ``view`` was fully written (by this or an earlier, interrupted run)."""
        e = self._views.get(view)
        return e is not None and e["status"] == STATUS_COMPLETE

    @property
    def completed_views(self) -> tuple[str, ...]:
        return tuple(sorted(v for v in self._views if self.is_complete(v)))

    @property
    def manifest(self) -> dict:
        """The manifest as last written (a fresh copy)."""
        import json

        return json.loads(self._manifest_bytes())

    # --- writing
    def write_cameras(self, views: Mapping[str, ViewCamera], spec: Mapping[str, Any]) -> None:
        """Write cameras.json for every view of the run, in order, and the resolved spec dict.

        Declares each view in the manifest (status ``pending`` until written).
        """
        entries = {}
        for name, vc in views.items():
            _check_view_name(name)
            entries[name] = vc.to_dict() if isinstance(vc, ViewCamera) else dict(vc)
        doc = {"format": FORMAT, "format_version": FORMAT_VERSION, "view_order": list(entries),
               "views": entries, "spec": spec}
        self.write_file(CAMERAS_NAME, sio.encode_json(doc), _flush=False)
        for name in entries:
            self._views.setdefault(name, {"status": STATUS_PENDING, "files": []})
        self._write_manifest()

    def write_mesh(self, name: str, mesh, *, vertex_normals: bool = False) -> str:
        """Write a world-frame trimesh as binary PLY at ``scene/meshes/<name>.ply``.

        trimesh stores vertices as float32 (the precision Mitsuba renders with); UVs and vertex
        colours are kept; vertex normals only if ``vertex_normals``. Returns the relative path.
        """
        from trimesh.exchange.ply import export_ply

        rel = mesh_path(name)
        # copy: trimesh's exporter adds UV attributes to the mesh it is given
        data = export_ply(mesh.copy(), encoding="binary", vertex_normal=vertex_normals)
        self.write_file(rel, data)
        return rel

    def write_file(self, rel_path: str, data: bytes, *, _flush: bool = True) -> str:
        """Write a dataset-level file (not tied to a view), atomically and hashed; returns its
        sha256. For example a calibration target's corner points as JSON."""
        _check_rel_path(rel_path)
        sha = sio.sha256_bytes(data)
        old = self._files.get(rel_path)
        if old is not None and old != sha:
            raise DatasetMismatchError(
                f"{rel_path} is already recorded in {self.root} with different content"
                f" (sha256 {old[:12]}... != {sha[:12]}...): outputs are not deterministic, or the"
                " dataset belongs to another run")
        sio.atomic_write_bytes(self.root / rel_path, data)
        self._files[rel_path] = sha
        if _flush:
            self._write_manifest()
        return sha

    def write_view(self, view: str, *, image, linear_rgb, truth,
                   extra_files: Mapping[str, bytes] | None = None) -> None:
        """Encode, write and hash one view's files, then mark it complete in the manifest.

        Arguments as in :func:`encode_view`; ``extra_files`` as in :func:`write_view_files`.
        """
        files = encode_view(view, image=image, linear_rgb=linear_rgb, truth=truth)
        files.update(_checked_extra_files(view, extra_files, files))
        hashes = {rel: sio.sha256_bytes(d) for rel, d in files.items()}
        self._check_rerecord(view, hashes)  # before writing anything
        for rel, data in files.items():
            sio.atomic_write_bytes(self.root / rel, data)
        self.record_view(view, hashes)

    def record_view(self, view: str, file_hashes: Mapping[str, str]) -> None:
        """Mark ``view`` complete with the files (``{relative path: sha256}``) already written,
        e.g. by :func:`write_view_files` in a worker; rewrites the manifest atomically."""
        self._record(view, file_hashes)
        self._write_manifest()

    def record_views(self, views: Mapping[str, Mapping[str, str]]) -> None:
        """:meth:`record_view` for several views (``{view: {relative path: sha256}}``, in order)
        with one manifest rewrite: the manifest's size grows with the run, so a client recording
        many workers' views batches what is ready. Nothing is recorded if any view is invalid."""
        views = dict(views)
        snapshot = ({v: {"status": e["status"], "files": list(e["files"])} for v, e in self._views.items()},
                    dict(self._files))
        try:
            for view, file_hashes in views.items():
                self._record(view, file_hashes)
        except Exception:
            self._views, self._files = snapshot
            raise
        self._write_manifest()

    def _record(self, view: str, file_hashes: Mapping[str, str]) -> None:
        _check_view_name(view)
        for rel, sha in file_hashes.items():
            _check_rel_path(rel)
            if not (isinstance(sha, str) and re.fullmatch(r"[0-9a-f]{64}", sha)):
                raise ValueError(f"{rel}: sha256 must be 64 lower-case hex digits, got {sha!r}")
        missing = sorted(set(view_paths(view).values()) - set(file_hashes))
        if missing:
            raise ValueError(f"view {view!r}: no hash for {missing}")
        self._check_rerecord(view, file_hashes)
        for rel in self._views.get(view, {}).get("files", []):
            self._files.pop(rel, None)
        self._files.update(file_hashes)
        self._views[view] = {"status": STATUS_COMPLETE, "files": sorted(file_hashes)}

    def close(self) -> None:
        """Write the manifest a last time (every method already leaves it up to date)."""
        self._write_manifest()

    def __enter__(self) -> "DatasetWriter":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # --- internals
    def _check_rerecord(self, view: str, hashes: Mapping[str, str]) -> None:
        _check_view_name(view)
        if self.is_complete(view):
            old = {rel: self._files.get(rel) for rel in self._views[view]["files"]}
            if old != dict(hashes):
                changed = sorted(r for r in set(old) | set(hashes) if old.get(r) != hashes.get(r))
                raise DatasetMismatchError(
                    f"view {view!r} is already complete in {self.root} with different files"
                    f" {changed}: outputs are not deterministic, or the dataset belongs to another run")
        own = set(self._views.get(view, {}).get("files", []))
        taken = sorted(rel for rel in hashes if rel in self._files and rel not in own)
        if taken:
            raise ValueError(f"view {view!r}: files {taken} already belong to another view or the dataset")

    def _manifest_bytes(self) -> bytes:
        body = dict(self._identity)
        body["views"] = {v: {"status": e["status"], "files": sorted(e["files"])}
                         for v, e in self._views.items()}
        body["files"] = dict(self._files)
        return _manifest_bytes(body)

    def _write_manifest(self) -> None:
        sio.atomic_write_bytes(self.root / MANIFEST_NAME, self._manifest_bytes())


# --- reader -----------------------------------------------------------------------------------
class Dataset:
    """Read-only access to a dataset directory (needs numpy, OpenCV and OpenEXR only).

    ``views`` lists the complete views in the run's order (cameras.json), ``all_views`` every
    declared view. File hashes are not checked here: use :func:`verify`.
    """

    def __init__(self, out_dir):
        self.root = Path(out_dir)
        self.manifest: dict = _load_manifest(self.root)
        self._cameras: dict | None = None

    @property
    def cameras(self) -> dict:
        """The parsed cameras.json (empty views if the run wrote none)."""
        if self._cameras is None:
            p = self.root / CAMERAS_NAME
            self._cameras = sio.read_json(p) if p.is_file() else {"view_order": [], "views": {}, "spec": None}
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
    def mesh_names(self) -> tuple[str, ...]:
        pre, suf = "scene/meshes/", ".ply"
        return tuple(sorted(r[len(pre):-len(suf)] for r in self.manifest["files"]
                            if r.startswith(pre) and r.endswith(suf)))

    def path(self, rel_path: str) -> Path:
        return self.root / rel_path

    def _paths(self, view: str) -> dict[str, Path]:
        e = self.manifest["views"].get(view)
        if e is None or e["status"] != STATUS_COMPLETE:
            state = "not in this dataset" if e is None else f"{e['status']}, not complete"
            raise KeyError(f"view {view!r} is {state}")
        return {k: self.root / rel for k, rel in view_paths(view).items()}

    def image(self, view: str) -> np.ndarray:
        """The rendered image: (H, W, 3) RGB or (H, W) grey, uint8 or uint16."""
        return sio.read_png(self._paths(view)["image"])

    def linear_image(self, view: str) -> np.ndarray:
        """Clean linear radiance, (H, W, 3) float32 RGB."""
        return sio.unpack_channels(sio.read_exr(self._paths(view)["linear"]), "", ("R", "G", "B"))

    def truth(self, view: str) -> dict[str, np.ndarray]:
        """Per-pixel truth of the ray through each pixel centre (keys :data:`TRUTH_KEYS`).

        depth_z, range (H, W) float32 metres (+inf on misses); points_world, points_cam,
        normals_world, normals_cam (H, W, 3) float32 (NaN on misses); uv (H, W, 2) float32;
        object_id, instance_id (H, W) uint32 (0 = none); valid (H, W) bool.
        """
        p = self._paths(view)
        ch = sio.read_exr(p["truth"])
        out: dict[str, np.ndarray] = {}
        for key, (prefix, comps) in _TRUTH_FLOAT_LAYOUT.items():
            out[key] = ch[prefix] if comps is None else sio.unpack_channels(ch, prefix, comps)
        ids = sio.read_exr(p["ids"])
        for key in _TRUTH_ID_KEYS:
            out[key] = ids[key]
        out["valid"] = sio.read_png(p["valid"]) == 255
        return out

    def view_info(self, view: str) -> dict:
        """The view's raw cameras.json entry (camera dict, cam_from_world, rig membership)."""
        try:
            return self.cameras["views"][view]
        except KeyError:
            raise KeyError(f"view {view!r} is not in {CAMERAS_NAME}") from None

    def camera(self, view: str):
        """``(Camera, cam_from_world: Rigid3)`` of a view."""
        from scenegen.camera import Camera

        info = self.view_info(view)
        return Camera.from_dict(info["camera"]), Rigid3.from_dict(info["cam_from_world"])

    def mesh(self, name: str):
        """A world-frame mesh as a trimesh.Trimesh."""
        import trimesh

        return trimesh.load(self.root / mesh_path(name), file_type="ply", process=False)


# --- verify -----------------------------------------------------------------------------------
@dataclass(frozen=True, kw_only=True)
class VerifyReport:
    """Result of :func:`verify`. Paths are relative POSIX paths, sorted."""

    ok: bool  # True iff every list below is empty
    missing: tuple[str, ...]  # listed in the manifest, absent on disk
    corrupted: tuple[str, ...]  # present, but the bytes differ from the recorded sha256
    unexpected: tuple[str, ...]  # on disk but not listed (e.g. files of unfinished views)
    incomplete_views: tuple[str, ...]  # declared views not marked complete
    problems: tuple[str, ...]  # anything else (unreadable manifest, inconsistent listings)
    files_checked: int  # number of files re-hashed

    def summary(self) -> str:
        lines = [f"{'OK' if self.ok else 'FAILED'}: {self.files_checked} files checked"]
        for label, items in (("missing", self.missing), ("corrupted", self.corrupted),
                             ("unexpected", self.unexpected),
                             ("incomplete views", self.incomplete_views), ("problems", self.problems)):
            if items:
                lines.append(f"{label} ({len(items)}):")
                lines.extend(f"  {x}" for x in items)
        return "\n".join(lines)


def _report(missing=(), corrupted=(), unexpected=(), incomplete=(), problems=(), checked=0):
    lists = [tuple(sorted(x)) for x in (missing, corrupted, unexpected, incomplete)]
    return VerifyReport(ok=not any(lists) and not problems, missing=lists[0], corrupted=lists[1],
                        unexpected=lists[2], incomplete_views=lists[3], problems=tuple(problems),
                        files_checked=checked)


def verify(out_dir) -> VerifyReport:
    """Re-hash every file listed in the manifest and compare the directory with it.

    The manifest checks itself (``manifest_sha256``); if it is corrupt nothing else can be
    trusted, and only ``manifest.json`` is reported.
    """
    root = Path(out_dir)
    mpath = root / MANIFEST_NAME
    if not root.is_dir():
        return _report(problems=[f"{root} is not a directory"])
    if not mpath.is_file():
        return _report(missing=[MANIFEST_NAME], problems=[f"no {MANIFEST_NAME}: not a scenegen dataset"])
    m, err = _manifest_integrity_error(mpath.read_bytes())
    if err:
        return _report(corrupted=[MANIFEST_NAME],
                       problems=[f"{MANIFEST_NAME}: {err}; other files not checked"])
    problems = []
    if m["format"] != FORMAT or m["format_version"] != FORMAT_VERSION:
        problems.append(f"format {m['format']!r} version {m['format_version']!r} is not"
                        f" {FORMAT!r} version {FORMAT_VERSION}")

    missing, corrupted = [], []
    for rel, sha in m["files"].items():
        try:
            _check_rel_path(rel)
        except ValueError as e:
            problems.append(str(e))
            continue
        p = root / rel
        if not p.is_file():
            missing.append(rel)
        elif sio.sha256_file(p) != sha:
            corrupted.append(rel)
    listed = set(m["files"]) | {MANIFEST_NAME}
    unexpected = [p.relative_to(root).as_posix() for p in root.rglob("*")
                  if p.is_file() and p.relative_to(root).as_posix() not in listed]

    incomplete = [v for v, e in m["views"].items() if e.get("status") != STATUS_COMPLETE]
    for v, e in m["views"].items():
        if e.get("status") == STATUS_COMPLETE:
            unlisted = sorted(set(view_paths(v).values()) - set(e.get("files", [])))
            unlisted += [r for r in e.get("files", []) if r not in m["files"]]
            if unlisted:
                problems.append(f"view {v!r} is complete but has no hash for {unlisted}")
    if CAMERAS_NAME in m["files"] and CAMERAS_NAME not in missing + corrupted:
        try:
            declared = sio.read_json(root / CAMERAS_NAME)["view_order"]
        except (ValueError, KeyError, TypeError) as e:
            problems.append(f"{CAMERAS_NAME}: unreadable ({e})")
        else:
            undeclared = sorted(set(declared) - set(m["views"]))
            if undeclared:
                problems.append(f"views in {CAMERAS_NAME} but not in {MANIFEST_NAME}: {undeclared}")
    return _report(missing, corrupted, unexpected, incomplete, problems, checked=len(m["files"]))
