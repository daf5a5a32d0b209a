"""The hostile command-line corpus (issue 25): options beyond the spec's limits and crafted,
re-signed sequence datasets, each through a ``scenegen`` or ``recon-eval`` command, with the
message fragment, what the line must name (the option or the file) and the exit code;
tests/hostile/test_hostile_command_corpus.py runs every case. The spec-side cases of the same
issue (environment maps, MTL images, a deep glTF, flow_steps, tracks.count, fps) are in
spec_corpus.py; the Python API's are API_CASES below."""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.codecs.tracks import TRACK_KEYS, encode_npz

#: A 3-frame sequence with flow and tracks at 48 x 36 (tests/scenegen/pipeline/test_sequence_runs.py's).
SEQUENCE_SPEC = """
name: hostile_seq
render: {spp: 4, max_depth: 2}
sequence: {fps: 20, frames: 3, flow_steps: [1], tracks: {count: 24, query_frames: [0]}}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, texture: {type: checkerboard, params: {squares_u: 6, squares_v: 6}}}
  - name: cube
    shape: {type: box, size: [0.3, 0.3, 0.3]}
    material: {type: diffuse, color: [0.8, 0.1, 0.1]}
    trajectory:
      keyframes:
        - {time_s: 0.0, translation: [-0.3, 0, 0.15]}
        - {time_s: 0.1, translation: [0.3, 0, 0.15], rotation_deg: [0, 0, 60]}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [48, 36], fx: 40}
views:
  - camera: cam
    trajectory:
      keyframes:
        - {time_s: 0.0, eye: [0, -2, 1.5], target: [0, 0, 0]}
        - {time_s: 0.1, eye: [0.2, -2, 1.5], target: [0, 0, 0]}
"""


def edit_index(edit):
    """A tamper of sequence/index.json (the caller re-signs the manifest)."""
    def tamper(root):
        p = root / "sequence" / "index.json"
        doc = json.loads(p.read_text())
        edit(doc)
        p.write_text(json.dumps(doc))
    return tamper


def nan_tracks(root):
    """Every truth track position NaN, every point still marked visible."""
    p = root / "sequence" / "tracks" / "cam.npz"
    with np.load(p, allow_pickle=False) as z:
        arrays = {k: z[k] for k in TRACK_KEYS}
    arrays["tracks_xy"] = np.full_like(arrays["tracks_xy"], np.nan)
    p.write_bytes(encode_npz(arrays))


def _set(path, value):
    def edit(doc):
        node = doc
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value
    return edit


#: (case id, tool: "scenegen" | "recon-eval", argv with {spec} {out} {data} {est} placeholders,
#:  tamper of the dataset (None: the command needs no rendered dataset), fragment, what the
#:  line must name: "option" (the option's name is in the fragment) or "data" (the tampered file))
CASES: list = []


def case(cid, tool, argv, tamper, fragment, names):
    CASES.append((cid, tool, tuple(argv), tamper, fragment, names))


SPP = "--spp: expected a whole number >= 1 and <= 65,536"
TILE = "--tile-width: expected 16 to 4,096 pixels"
# --- options held to the spec's limits (before anything is rendered, read or written) ------------
case("preview_spp_1e9", "scenegen", ["preview", "{spec}", "-o", "{out}/p.png", "--spp", "1000000000"], None, SPP, "option")
case("preview_spp_0", "scenegen", ["preview", "{spec}", "-o", "{out}/p.png", "--spp", "0"], None, SPP, "option")
case("preview_tile_width_1e8", "scenegen", ["preview", "{spec}", "-o", "{out}/p.png", "--tile-width", "100000000"],
     None, TILE, "option")
case("preview_tile_width_8", "scenegen", ["preview", "{spec}", "-o", "{out}/p.png", "--tile-width", "8"], None, TILE,
     "option")
case("gallery_tile_width_1e8", "scenegen", ["gallery", "{out}", "--tile-width", "100000000"], None, TILE, "option")
case("render_spp_1e9", "scenegen", ["render", "{spec}", "-o", "{out}/r", "--spp", "1000000000"], None, SPP, "option")
case("render_seed_2_64", "scenegen", ["render", "{spec}", "-o", "{out}/r", "--seed", "18446744073709551616"], None,
     "--seed: expected a whole number >= 0 and <= 4,294,967,295", "option")
# --- names in sequence/index.json checked where the index is read, for every export -------------
VIEW = "lists an invalid view name: view name '../x'"
for fmt in ("kitti-flow", "sintel", "tapvid", "tracks-video", "kitti-sceneflow"):
    case(f"export_{fmt}_pair_view_dotdot", "scenegen", ["export", "{data}", "--format", fmt, "-o", "{out}/e"],
         edit_index(_set(["pairs", 0, "b"], "../x")), VIEW, "data")
case("export_tapvid_track_frame_dotdot", "scenegen", ["export", "{data}", "--format", "tapvid", "-o", "{out}/e"],
     edit_index(_set(["tracks", 0, "frames", 1], "../x")), VIEW, "data")
case("export_tapvid_stream_dotdot", "scenegen", ["export", "{data}", "--format", "tapvid", "-o", "{out}/e"],
     edit_index(_set(["tracks", 0, "stream"], "../t")), "lists an invalid stream name", "data")
# --- truth tracks that are NaN where visible: one check on every read (scenegen.dataset.codecs.tracks)
NAN = "is visible (not occluded) but not finite"
case("export_tapvid_nan_tracks", "scenegen", ["export", "{data}", "--format", "tapvid", "-o", "{out}/e"], nan_tracks,
     NAN, "data")
case("export_tracks_video_nan_tracks", "scenegen", ["export", "{data}", "--format", "tracks-video", "-o", "{out}/e"],
     nan_tracks, NAN, "data")
case("recon_eval_tracks_nan_tracks", "recon-eval", ["tracks", "{est}", "{data}", "--stream", "cam", "--quiet"],
     nan_tracks, NAN, "data")


def api_cases():
    """(case id, call, exception type, fragment) of the Python API's argument checks."""
    from scenegen import api

    return [
        ("scene_objects_not_a_list", lambda: api.Scene(objects="notalist"), api.SpecError,
         "<python>: objects: expected a list of SceneObject, got str"),
        ("scene_objects_item", lambda: api.Scene(objects=[42]), api.SpecError,
         "<python>: objects[0]: expected a SceneObject, got int 42"),
        ("scene_lights_not_a_list", lambda: api.Scene(lights="sun"), api.SpecError, "<python>: lights: expected a list"),
        ("scene_cameras_item", lambda: api.Scene(cameras={"cam": 3}), api.SpecError,
         "<python>: cameras.cam: expected a CameraSpec, got int 3"),
        ("scene_rigs_item", lambda: api.Scene(rigs=[1]), api.SpecError, "<python>: rigs[0]: expected a Rig"),
        ("scene_views_item", lambda: api.Scene(views=[None]), api.SpecError, "<python>: views[0]: expected a ViewSet"),
        ("scene_materials_item", lambda: api.Scene(materials={"red": "red"}), api.SpecError,
         "<python>: materials.red: expected a DiffuseMaterial"),
        ("scene_render_type", lambda: api.Scene(render=42), api.SpecError,
         "<python>: render: expected RenderSettings or None, got int 42"),
        ("scene_crossview_type", lambda: api.Scene(crossview="yes"), api.SpecError,
         "<python>: crossview: expected a CrossviewSpec or None"),
        ("to_yaml_not_a_spec", lambda: api.to_yaml(42), TypeError, "to_yaml(spec): expected a SceneSpec"),
        ("check_spec_not_a_spec", lambda: api.check_spec(None), TypeError, "check_spec(spec): expected a SceneSpec"),
        ("render_not_a_spec", lambda: api.render({"name": "x"}, "out"), TypeError,
         "check_spec(spec): expected a SceneSpec"),
    ]
