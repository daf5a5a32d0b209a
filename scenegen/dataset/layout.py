"""Where every file of a dataset lives: the only module that spells out the layout.

All paths are relative POSIX paths inside the dataset folder (documented for readers outside
this project in docs/dataset_format.md and docs/crossview.md)::

    manifest.json                           format, spec hash, seed, variant, versions, status, hashes
    manifest.journal                        only while a run writes: views recorded since (journal.py)
    cameras.json                            per view: camera, cam_from_world, rig, optics, lights; the spec
    scene/meshes/<object>.ply               world-frame meshes
    scene/targets/<object>.json             calibration-target points (board and world frame)
    images/<view>.png                       rendered image, uint8 or uint16, RGB or grey
    images/<view>_linear.exr                clean linear float32 RGB (R, G, B)
    truth/<view>.exr                        float32 truth channels (depth_z, range, P_world.X, ...)
    truth/<view>_ids.exr                    uint32 object_id, instance_id (0 = nothing)
    truth/<view>_valid.png                  uint8 mask, 255 where the pixel centre's ray hit
    truth/<view>_vignetting.exr             the imaging chain's vignetting map (channel V)
    truth/<view>_albedo.exr                 diffuse albedo per pixel centre (albedo.R/G/B; spec truth.albedo)
    truth/<view>_lights.json                the lights on in the view, camera frame (spec truth.lights)
    truth/<view>_coc.exr                    thin-lens circle of confusion per pixel (channel coc_radius_px; truth.defocus)
    truth/<view>_boxes.json                 2D and 3D bounding boxes per object (truth.boxes)
    truth/<view>_objects.json               annotated objects: poses, visible fraction, keypoints (truth.objects)
    truth/<view>_objects.npz                their full (amodal) masks, packed bits (truth.objects)
    truth/<view>_projector.npz              a projector-lit view: projector pixel, lit mask, codes per pixel
    patterns/<view>/sequence.json           a projector-lit view: the projector, its pose and the patterns
    patterns/<view>/<k>.png                 the view under pattern k (k = 000, 001, ...; encoded as images/)
    patterns/<view>/<k>_linear.exr          ... its clean linear float32 RGB (projector linear_patterns)
    raw/<view>.dng                          the sensor's raw mosaic as DNG (cameras with imaging.raw)
    images/<view>_raw.png                   the same mosaic as a 16-bit grey PNG (imaging.raw.png)
    crossview/index.json                    what cross-view truth the run wrote
    crossview/corr/<i>/<j>.exr              dense correspondences i -> j (u, v, z, state)
    crossview/flow/<i>/<j>.flo              optical flow i -> j
    crossview/twoview/<i>/<j>.json          relative pose, E, F, epipoles, plane homographies
    crossview/matches/<i>/<j>_<kind>.npy    labelled putative matches (kind: synthetic, sift)
    crossview/targets/<view>.json           per-view calibration-target truth
    crossview/stereo/<left view>/<file>     rectified pair: STEREO_FILES
    sequence/index.json                     what the sequence stage wrote (pairs, tracks)
    sequence/objects.json                   every object's world_from_object, presence, velocities per frame
    sequence/motion/<a>/<b>.exr             flow, scene flow, depth in b, occlusion state of a's pixels at b
    sequence/flow/<a>/<b>.flo               optical flow a -> b (moving objects moved)
    sequence/stereo_motion/<a>/<b>.exr      a stereo rig's rectified left a -> b: flow, depth and disparity
                                            at b, states in b's rectified left and right views
    sequence/tracks/<stream>.npz            TAP-Vid-style point tracks of a camera stream
    streams/<name>/stream.json              a sensor stream beside the views (streams.py): kind, sensor,
                                            schema, chunks with their sample counts and time ranges
    streams/<name>/chunk_<k>.npz            the samples of chunk k: time_s and one array per field

Every name that becomes part of a path is checked here (:func:`check_name`): names read from a
spec or from a dataset's own JSON never reach the file system unchecked.
"""
from __future__ import annotations

import re

MANIFEST = "manifest.json"
MANIFEST_JOURNAL = "manifest.journal"
CAMERAS = "cameras.json"

# View, object and mesh names become file names: keep them portable (no separators, no '..').
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
MAX_NAME_LEN = 128
#: A view name may not end like another view's suffixed files (view "a_ids" would clash with
#: view "a"'s truth/a_ids.exr).
RESERVED_VIEW_SUFFIXES = ("_linear", "_ids", "_valid", "_vignetting", "_raw", "_albedo", "_lights", "_coc",
                          "_boxes", "_objects", "_projector")
MATCH_KINDS = ("synthetic", "sift")

CROSSVIEW = "crossview"
CROSSVIEW_INDEX = f"{CROSSVIEW}/index.json"
#: Files of a rectified stereo frame, by key, with {side} = left | right.
STEREO_FILES = {
    "image": "{side}.png", "linear": "{side}_linear.exr", "disparity_pfm": "disp_{side}.pfm",
    "disparity_occ": "disp_{side}_occ.png", "disparity_noc": "disp_{side}_noc.png",
    "correspondence": "corr_{side}.exr", "map": "map_{side}.exr", "ids": "ids_{side}.exr",
    # active IR stereo (a rig with a projector, docs/dataset_format.md "Active IR stereo")
    "ir": "ir_{side}.png", "ir_off": "ir_off_{side}.png", "ir_invalid": "ir_invalid_{side}.png",
}
STEREO_CALIB = "calib.json"
STEREO_SIDES = ("left", "right")


def check_name(kind: str, name: str) -> str:
    """``name`` if it is 1-128 characters of [A-Za-z0-9_.-] starting with a letter or digit;
    ValueError naming ``kind`` otherwise."""
    if not isinstance(name, str) or not NAME_RE.match(name) or len(name) > MAX_NAME_LEN:
        raise ValueError(
            f"{kind} name {name!r} must be 1-{MAX_NAME_LEN} characters from [A-Za-z0-9_.-],"
            " starting with a letter or digit")
    return name


def check_view_name(view: str) -> str:
    check_name("view", view)
    if view.endswith(RESERVED_VIEW_SUFFIXES):
        raise ValueError(f"view name {view!r} must not end with {RESERVED_VIEW_SUFFIXES}"
                         " (its files would collide with another view's)")
    return view


def check_rel_path(rel: str) -> str:
    """A relative POSIX path inside the dataset: not the manifest, no '..', no hidden parts."""
    if not isinstance(rel, str) or not rel or rel.startswith("/") or "\\" in rel:
        raise ValueError(f"dataset paths must be relative POSIX paths, got {rel!r}")
    parts = rel.split("/")
    if any(p in ("", ".", "..") or p.startswith(".") for p in parts):
        raise ValueError(f"dataset path {rel!r} has an empty, '.', '..' or hidden component")
    if rel in (MANIFEST, MANIFEST_JOURNAL):
        raise ValueError(f"{rel} is written by the dataset writer only")
    return rel


def check_listed_names(source: str, *, views=(), paths=(), names=()) -> None:
    """Check names *read from a file* (a manifest, cameras.json, the cross-view index) before any
    of them reaches a path: every view against :func:`check_view_name`, every relative path
    against :func:`check_rel_path`. ValueError naming ``source`` and the first bad name: a
    crafted file cannot make a reader (or an export) read or write outside the dataset."""
    for v in views:
        try:
            check_view_name(v)
        except ValueError as e:
            raise ValueError(f"{source}: lists an invalid view name: {e}") from None
    for r in paths:
        try:
            check_rel_path(r)
        except ValueError as e:
            raise ValueError(f"{source}: lists an invalid path: {e}") from None
    for kind, n in names:  # other names tools make files of (camera, rig, rig member, scene)
        try:
            check_name(kind, n)
        except ValueError as e:
            raise ValueError(f"{source}: lists an invalid {kind} name: {e}") from None


# --- per view ----------------------------------------------------------------------------------
def view_paths(view: str) -> dict[str, str]:
    """Relative paths of a view's standard files: keys image, linear, truth, ids, valid."""
    check_view_name(view)
    return {
        "image": f"images/{view}.png",
        "linear": f"images/{view}_linear.exr",
        "truth": f"truth/{view}.exr",
        "ids": f"truth/{view}_ids.exr",
        "valid": f"truth/{view}_valid.png",
    }


#: The imaging chain's vignetting map of a view (one float32 channel, VIGNETTING_CHANNEL); the
#: template is recorded in cameras.json.
VIGNETTING_TEMPLATE = "truth/{view}_vignetting.exr"
VIGNETTING_CHANNEL = "V"


def vignetting_path(view: str) -> str:
    """The imaging chain's vignetting map of a view (an extra file of the view)."""
    return VIGNETTING_TEMPLATE.format(view=check_view_name(view))


#: Albedo and light truth of a view (written when the spec's ``truth:`` asks for them).
ALBEDO_TEMPLATE = "truth/{view}_albedo.exr"
LIGHTS_TEMPLATE = "truth/{view}_lights.json"


def albedo_path(view: str) -> str:
    """The diffuse albedo map of a view (an extra file of the view)."""
    return ALBEDO_TEMPLATE.format(view=check_view_name(view))


COC_TEMPLATE = "truth/{view}_coc.exr"
COC_CHANNEL = "coc_radius_px"


def coc_path(view: str) -> str:
    """The thin-lens circle of confusion of a view's pixels (an extra file of the view)."""
    return COC_TEMPLATE.format(view=check_view_name(view))


def lights_path(view: str) -> str:
    """The calibrated lights of a view, in its camera frame (an extra file of the view)."""
    return LIGHTS_TEMPLATE.format(view=check_view_name(view))


BOXES_TEMPLATE = "truth/{view}_boxes.json"


def boxes_path(view: str) -> str:
    """The 2D and 3D bounding boxes of every object in a view (an extra file of the view)."""
    return BOXES_TEMPLATE.format(view=check_view_name(view))


OBJECTS_TEMPLATE = "truth/{view}_objects.json"
OBJECT_MASKS_TEMPLATE = "truth/{view}_objects.npz"


def objects_path(view: str) -> str:
    """The annotated objects' truth of a view (an extra file of the view)."""
    return OBJECTS_TEMPLATE.format(view=check_view_name(view))


def object_masks_path(view: str) -> str:
    """The annotated objects' full masks of a view (an extra file of the view)."""
    return OBJECT_MASKS_TEMPLATE.format(view=check_view_name(view))


#: The raw mosaic of a view of a camera with ``imaging.raw`` (templates recorded in cameras.json).
RAW_DNG_TEMPLATE = "raw/{view}.dng"
RAW_PNG_TEMPLATE = "images/{view}_raw.png"


PATTERNS_DIR = "patterns"


def projector_truth_path(view: str) -> str:
    """``truth/<view>_projector.npz``: a projector-lit view's per-pixel projector truth
    (:mod:`scenegen.dataset.structured_light`)."""
    return f"truth/{check_view_name(view)}_projector.npz"


def pattern_sequence_path(view: str) -> str:
    """``patterns/<view>/sequence.json``: the projector, its pose and the patterns of a view."""
    return f"{PATTERNS_DIR}/{check_view_name(view)}/sequence.json"


def pattern_image_path(view: str, k: int) -> str:
    """``patterns/<view>/<k>.png``: the view under pattern ``k`` (three digits)."""
    return f"{PATTERNS_DIR}/{check_view_name(view)}/{_pattern_index(k)}.png"


def pattern_linear_path(view: str, k: int) -> str:
    """``patterns/<view>/<k>_linear.exr``: the clean linear render under pattern ``k``."""
    return f"{PATTERNS_DIR}/{check_view_name(view)}/{_pattern_index(k)}_linear.exr"


def _pattern_index(k: int) -> str:
    if isinstance(k, bool) or int(k) != k or not 0 <= int(k) < 1000:
        raise ValueError(f"pattern index must be an integer in [0, 999], got {k!r}")
    return f"{int(k):03d}"


def raw_dng_path(view: str) -> str:
    """The raw mosaic of a view as DNG (an extra file of the view)."""
    return RAW_DNG_TEMPLATE.format(view=check_view_name(view))


def raw_png_path(view: str) -> str:
    """The raw mosaic of a view as a 16-bit grey PNG (an extra file of the view)."""
    return RAW_PNG_TEMPLATE.format(view=check_view_name(view))


# --- the scene ---------------------------------------------------------------------------------
MESHES_DIR = "scene/meshes"
TARGETS_DIR = "scene/targets"


def mesh_path(name: str) -> str:
    """A world-frame mesh."""
    return f"{MESHES_DIR}/{check_name('mesh', name)}.ply"


def target_path(name: str) -> str:
    """A calibration target's points (board and world frame)."""
    return f"{TARGETS_DIR}/{check_name('target', name)}.json"


def names_under(files, directory: str, suffix: str) -> tuple[str, ...]:
    """Sorted names ``<name>`` of the listed files ``<directory>/<name><suffix>``."""
    pre = directory + "/"
    return tuple(sorted(r[len(pre):-len(suffix)] for r in files
                        if r.startswith(pre) and r.endswith(suffix) and "/" not in r[len(pre):]))


# --- cross-view truth --------------------------------------------------------------------------
def correspondence_path(i: str, j: str) -> str:
    return f"{CROSSVIEW}/corr/{check_view_name(i)}/{check_view_name(j)}.exr"


def flow_path(i: str, j: str) -> str:
    return f"{CROSSVIEW}/flow/{check_view_name(i)}/{check_view_name(j)}.flo"


def twoview_path(i: str, j: str) -> str:
    return f"{CROSSVIEW}/twoview/{check_view_name(i)}/{check_view_name(j)}.json"


def matches_path(i: str, j: str, kind: str) -> str:
    if kind not in MATCH_KINDS:
        raise ValueError(f"match kind must be one of {MATCH_KINDS}, got {kind!r}")
    return f"{CROSSVIEW}/matches/{check_view_name(i)}/{check_view_name(j)}_{kind}.npy"


def view_targets_path(view: str) -> str:
    return f"{CROSSVIEW}/targets/{check_view_name(view)}.json"


def stereo_dir(left_view: str) -> str:
    return f"{CROSSVIEW}/stereo/{check_view_name(left_view)}"


def stereo_path(left_view: str, key: str, side: str | None = None) -> str:
    """A file of the rectified frame of ``left_view``: ``key`` of :data:`STEREO_FILES` with a
    side, or ``"calib"``."""
    if key == "calib":
        return f"{stereo_dir(left_view)}/{STEREO_CALIB}"
    if side not in STEREO_SIDES or key not in STEREO_FILES:
        raise ValueError(f"stereo file: key one of {list(STEREO_FILES)} or 'calib', side one of {STEREO_SIDES};"
                         f" got {key!r}, {side!r}")
    return f"{stereo_dir(left_view)}/{STEREO_FILES[key].format(side=side)}"


# --- sequences (moving scenes) -----------------------------------------------------------------
SEQUENCE = "sequence"
SEQUENCE_INDEX = f"{SEQUENCE}/index.json"
SEQUENCE_OBJECTS = f"{SEQUENCE}/objects.json"


def motion_path(a: str, b: str) -> str:
    """Flow, scene flow, depth and state of view a's pixels at view b (EXR)."""
    return f"{SEQUENCE}/motion/{check_view_name(a)}/{check_view_name(b)}.exr"


def sequence_flow_path(a: str, b: str) -> str:
    """Optical flow a -> b of a sequence, Middlebury .flo."""
    return f"{SEQUENCE}/flow/{check_view_name(a)}/{check_view_name(b)}.flo"


def stereo_motion_path(a: str, b: str) -> str:
    """Flow, depth, disparity and states at b of the rectified left view of stereo frame a (EXR;
    a, b: the frames' left views)."""
    return f"{SEQUENCE}/stereo_motion/{check_view_name(a)}/{check_view_name(b)}.exr"


def tracks_path(stream: str) -> str:
    """Point tracks of a camera stream (view set prefix, with the rig member), NPZ."""
    return f"{SEQUENCE}/tracks/{check_name('stream', stream)}.npz"


# --- streams (samples of sensors beside the views) ---------------------------------------------
STREAMS = "streams"


def stream_doc_path(name: str) -> str:
    """A stream's description (JSON, written when the stream is complete)."""
    return f"{STREAMS}/{check_name('stream', name)}/stream.json"


def stream_chunk_path(name: str, index: int) -> str:
    """Chunk ``index`` (0, 1, ...) of a stream's samples (NPZ)."""
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < 1_000_000:
        raise ValueError(f"stream chunk index must be an int in [0, 999999], got {index!r}")
    return f"{STREAMS}/{check_name('stream', name)}/chunk_{index:06d}.npz"
