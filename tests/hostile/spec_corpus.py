"""The hostile spec corpus (issue 18): each case is a small edit of one good spec, the message
fragment ``scenegen validate`` must print and the exit code. Generated from this table, not
stored as files; tests/hostile/test_hostile_spec_corpus.py runs every case through the CLI."""
from __future__ import annotations

import json

import cv2
import numpy as np

from scenegen.dataset.codecs import pack_channels, write_exr

BASE = """name: corpus
render: {spp: 4, max_depth: 3, seed: 1}
objects:
  - name: floor
    shape: {type: plane, size: [3, 3]}
    material: {type: diffuse, color: 0.5}
  - name: ball
    shape: {type: sphere, radius: 0.3}
    transform: {translation: [0, 0, 0.3]}
    material: {type: diffuse, color: [0.8, 0.2, 0.1]}
lights:
  - {type: point, position: [1, -1, 2], intensity: 5}
cameras:
  cam: {model: opencv, size: [64, 48], fx: 60, fy: 60, cx: 32, cy: 24, dist: [-0.1, 0.01, 0, 0]}
views:
  - camera: cam
    orbit: {center: [0, 0, 0], radius_m: 2.0, elevations_deg: [30], count: 3}
"""

FINITE = "expected a finite number"
NUMBER = "expected a number"


def sub(old: str, new: str):
    def edit(text: str) -> str:
        assert old in text, old
        return text.replace(old, new, 1)
    return edit


def append(extra: str):
    return lambda text: text + extra


def whole(new):
    return lambda text: new


def raw(data: bytes):
    return data  # the file's bytes as they are


#: (case id, edit or raw bytes, message fragment, exit code)
CASES: list = []


def case(cid, edit, fragment, code=2):
    CASES.append((cid, edit, fragment, code))


# --- numbers: NaN, infinity, beyond float64, strings, ranges, the limits -------------------------
for field, old in [("spp", "spp: 4"), ("max_depth", "max_depth: 3"), ("seed", "seed: 1")]:
    key = old.split(":")[0]
    case(f"{field}_nan", sub(old, f"{key}: .nan"), "(NaN)")
    case(f"{field}_inf", sub(old, f"{key}: .inf"), "(infinity)")
    case(f"{field}_text", sub(old, f"{key}: many"), "expected an integer")
    case(f"{field}_fraction", sub(old, f"{key}: 2.5"), "expected an integer")
    case(f"{field}_list", sub(old, f"{key}: [4]"), "expected an integer")
case("spp_zero", sub("spp: 4", "spp: 0"), "expected a value >= 1")
case("spp_1e9", sub("spp: 4", "spp: 1000000000"), "<= 65536")
case("spp_1e40", sub("spp: 4", "spp: 1e40"), "<= 65536")
case("spp_huge_int", sub("spp: 4", "spp: " + "9" * 400), "-digit integer")
case("seed_negative", sub("seed: 1", "seed: -1"), "expected a value >= 0")
case("seed_2_64", sub("seed: 1", "seed: 18446744073709551616"), "<= 4294967295")
for name, value, frag in [("nan", ".nan", "(NaN)"), ("inf", ".inf", "(infinity)"), ("neg_inf", "-.inf", "(infinity)"),
                          ("text", "wide", NUMBER), ("1e400", "1e400", "1e400 (infinity)"),
                          ("zero", "0", "expected a value >"), ("negative", "-60", "expected a value >")]:
    case(f"fx_{name}", sub("fx: 60,", f"fx: {value},"), frag)
for name, value, frag in [("nan", ".nan", "(NaN)"), ("inf", ".inf", "(infinity)"), ("text", "big", NUMBER),
                          ("zero", "0", "expected a value >"), ("negative", "-0.3", "expected a value >")]:
    case(f"radius_{name}", sub("radius: 0.3", f"radius: {value}"), frag)
for name, value, frag in [("nan", "[.nan, 0, 0.3]", "(NaN)"), ("inf", "[0, .inf, 0.3]", "(infinity)"),
                          ("two", "[0, 0]", "expected 3 numbers"), ("four", "[0, 0, 0, 0]", "expected 3 numbers"),
                          ("text", "[0, a, 0]", "expected 3 numbers"), ("scalar", "0", "expected 3 numbers")]:
    case(f"translation_{name}", sub("translation: [0, 0, 0.3]", f"translation: {value}"), frag)
for name, value, frag in [("nan", "[.nan, 0.2, 0.1]", "(NaN)"), ("negative", "[-1, 0.2, 0.1]", "expected a value >= 0"),
                          ("two", "[0.8, 0.2]", "expected 3 numbers"), ("text", "red", "expected a number or 3 numbers")]:
    case(f"color_{name}", sub("color: [0.8, 0.2, 0.1]", f"color: {value}"), frag)
for name, value, frag in [("nan", ".nan", "(NaN)"), ("negative", "-5", "expected a value >= 0"), ("text", "bright", NUMBER)]:
    case(f"intensity_{name}", sub("intensity: 5", f"intensity: {value}"), frag)
# --- image sizes and counts: the limits, checked before anything is allocated ---------------------
for name, value, frag in [("100000", "[100000, 100000]", "at most 16384 pixels"),
                          ("4e9", "[4000000000, 1]", "at most 16384 pixels"),
                          ("pixels", "[16384, 16384]", "pixels per image"),
                          ("nan", "[.nan, 48]", "(NaN)"), ("inf", "[64, .inf]", "(infinity)"),
                          ("negative", "[-64, 48]", "positive whole number of pixels"),
                          ("fraction", "[64.5, 48]", "positive whole number of pixels"),
                          ("zero", "[0, 48]", "positive whole number of pixels"),
                          ("one_number", "[64]", "expected 2 numbers"), ("text", "big", "expected 2 numbers"),
                          ("three", "[64, 48, 3]", "expected 2 numbers")]:
    case(f"size_{name}", sub("size: [64, 48]", f"size: {value}"), frag)
for name, value, frag in [("1e8", "100000000", "<= 1000000"), ("zero", "0", "expected a value >= 1"),
                          ("nan", ".nan", "(NaN)"), ("fraction", "2.5", "expected an integer"),
                          ("negative", "-3", "expected a value >= 1"), ("text", "three", "expected an integer")]:
    case(f"orbit_count_{name}", sub("count: 3}", f"count: {value}}}"), frag)
case("orbit_total_views", sub("elevations_deg: [30], count: 3", "elevations_deg: [10, 20, 30, 40, 50], count: 500000"),
     "at most 1,000,000 per run")
for name, value, frag in [("90", "[90]", "strictly between -90 and 90"), ("nan", "[.nan]", "(NaN)"),
                          ("empty", "[]", "expected a list of numbers")]:
    case(f"elevation_{name}", sub("elevations_deg: [30]", f"elevations_deg: {value}"), frag)
case("radius_m_zero", sub("radius_m: 2.0", "radius_m: 0"), "expected a value >")
# --- distortion, camera models ------------------------------------------------------------------
case("dist_7", sub("dist: [-0.1, 0.01, 0, 0]", "dist: [0, 0, 0, 0, 0, 0, 0]"), "dist")
case("dist_3", sub("dist: [-0.1, 0.01, 0, 0]", "dist: [0, 0, 0]"), "dist")
case("dist_nan", sub("dist: [-0.1, 0.01, 0, 0]", "dist: [.nan, 0, 0, 0]"), "(NaN)")
case("model_unknown", sub("model: opencv", "model: opencv2"), "expected one of")
case("fx_and_fov", sub("fx: 60,", "fov_deg: 60, fx: 60,"), "give either fov_deg or fx and fy")
# --- YAML itself: tags, nesting, aliases, duplicates, encodings, binary ---------------------------
case("tag_binary", sub("name: corpus", "name: !!binary x"), "cannot read the value !!binary x")
for tag in ["!!python/name:os.system", "!!python/object/apply:os.system", "!!python/object:object",
            "!custom", "!!python/module:os"]:
    case(f"tag_{tag.strip('!').replace('/', '_').replace(':', '_')}", sub("name: corpus", f"name: {tag} x"),
         "is not allowed")
case("deep_flow", append("variation: " + "[" * 3000 + "]" * 3000 + "\n"), "nesting deeper than 64 levels")
case("deep_block", append("variation:\n" + "".join("  " * i + f"k{i}:\n" for i in range(1, 80)) + "  " * 80 + "x: 1\n"),
     "nesting deeper than 64 levels")
case("alias_bomb", append("".join(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9 if i else ["1"] * 9) + "]\n"
                                  for i in range(9))), "when its aliases (*name) are followed")
case("alias_recursive", append("loop: &l [*l]\n"), "alias")
case("alias_undefined", append("x: *nowhere\n"), "invalid YAML")
for key, old, new in [("name", "name: corpus", "name: corpus\nname: x"), ("spp", "spp: 4,", "spp: 4, spp: 2,"),
                      ("radius", "radius: 0.3", "radius: 0.3, radius: 1"), ("fx", "fx: 60,", "fx: 60, fx: 2,"),
                      ("views_key", "views:", "views: []\nviews:")]:
    case(f"duplicate_{key}", sub(old, new), f"duplicate key '{key.split('_')[0]}'")
case("duplicate_object_name", sub("  - name: ball", "  - name: floor"), "floor")
case("unknown_top_key", append("renderer: {spp: 4}\n"), "unknown key 'renderer'")
case("unknown_object_key", sub("    transform:", "    transfrom:"), "unknown key 'transfrom'")
case("unknown_render_key", sub("spp: 4", "spp: 4, spps: 8"), "unknown key 'spps'")
case("empty_file", whole(""), "got an empty document")
case("top_level_list", whole("- a\n- b\n"), "a mapping at the top level")
case("top_level_scalar", whole("hello\n"), "a mapping at the top level")
case("bad_indent", whole("name: x\n  objects: [\n"), "invalid YAML")
case("tab_indent", whole("name: x\nobjects:\n\t- a\n"), "invalid YAML")
case("binary_png", raw(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR"), "NUL byte (is this a binary file?)")
case("binary_random", raw(bytes(range(256)) * 4), "NUL byte")
case("utf16_le", raw(BASE.encode("utf-16")), "UTF-16 encoded; save it as UTF-8")
case("utf16_be", raw(b"\xfe\xff" + BASE.encode("utf-16-be")), "UTF-16 encoded")
case("utf32", raw(BASE.encode("utf-32")), "UTF-32 encoded")
case("latin1", raw(BASE.replace("corpus", "caf\u00e9").encode("latin-1")), "not UTF-8 text")
case("control_char", sub("name: corpus", "name: cor\x07pus"), "is not allowed in YAML text")
case("utf8_bom_ok", lambda t: "\ufeff" + t, "OK", 0)
# --- names --------------------------------------------------------------------------------------
case("object_name_5000", sub("  - name: ball", "  - name: " + "b" * 5000), "at most 128 characters")
case("object_name_slash", sub("  - name: ball", "  - name: ../ball"), "letters, digits")
case("object_name_space", sub("  - name: ball", "  - name: 'my ball'"), "letters, digits")
case("object_name_number", sub("  - name: ball", "  - name: 12"), "expected an object name")
case("scene_name_dots", sub("name: corpus", "name: '..'"), "letters, digits")
case("scene_name_5000", sub("name: corpus", "name: " + "s" * 5000), "at most 128 characters")
case("camera_name_slash", sub("  cam: {", "  'a/b': {"), "expected a camera name made of letters")
case("light_name_null_is_absent", sub("{type: point,", "{type: point, name: null,"), "OK", 0)
# --- files the spec names -----------------------------------------------------------------------
MESH = "  - name: thing\n    mesh: {path}\n    material: {{type: diffuse, color: 0.5}}\n"
TEX = "  - name: tex\n    shape: {{type: box, size: [1, 1, 1]}}\n    material: {{type: diffuse, texture: {{type: image, path: {path}}}}}\n"
for name, path, frag in [("nan_vertex", "nan.obj", "is not finite"), ("bad_index", "range.obj", "could not be read"),
                         ("empty_mesh", "empty.obj", "the file is empty"), ("no_faces", "nofaces.obj", "no triangles"),
                         ("garbage_ply", "garbage.ply", "could not be read"), ("directory", "dir.obj", "is a directory"),
                         ("missing", "missing.obj", "file not found"), ("suffix", "mesh.txt", "expected a mesh file"),
                         ("nul_byte", '"a\\0b.obj"', "NUL byte"), ("empty_path", '""', "expected a file path")]:
    case(f"mesh_{name}", sub("lights:", MESH.format(path=path) + "lights:"), frag)
for name, path, frag in [("empty_png", "empty.png", "the file is empty"), ("corrupt_png", "corrupt.png", "could not decode"),
                         ("directory", "dir.png", "is a directory"), ("missing", "missing.png", "file not found"),
                         ("truncated_png", "truncated.png", "could not decode")]:
    case(f"texture_{name}", sub("lights:", TEX.format(path=path) + "lights:"), frag)
case("texture_size_huge", sub("color: 0.5}", "texture: {type: noise, params: {size_px: 1000000}}}"),
     "more than 67,108,864 pixels")
case("texture_checker_huge", sub("color: 0.5}", "texture: {type: checkerboard, params: {squares_u: 100000, "
                                 "squares_v: 100000}}}"), "more than 67,108,864 pixels")
case("texture_size_negative", sub("color: 0.5}", "texture: {type: speckle, params: {size_px: -4}}}"), "must be positive")
case("texture_size_text", sub("color: 0.5}", "texture: {type: natural, params: {size_px: big}}}"),
     "size_px must be an int")
# --- environment maps: read as render reads them, the size by the header before allocation (issue 25)
ENV = "  - {{type: envmap, path: {path}}}\n"
for name, path, frag in [("text_exr", "text.exr", "not a readable EXR file"), ("empty_hdr", "empty.hdr", "the file is empty"),
                         ("hdr_100000x1", "wide.hdr", "could not decode it"),
                         ("hdr_100000x100000", "huge.hdr", "100000 x 100000 pixels by its header"),
                         ("hdr_no_header", "noheader.hdr", "not a Radiance HDR file"),
                         ("exr_nan", "nan.exr", "values are not finite"), ("exr_uv", "uv.exr", "expected channels R, G, B"),
                         ("png_garbage", "corrupt.png", "not a readable PNG image"), ("tif", "env.tif", "expected a environment image file"),
                         ("directory", "dir.exr", "is a directory"), ("ok_hdr", "ok.hdr", "OK"), ("ok_exr", "ok.exr", "OK")]:
    case(f"envmap_{name}", sub("lights:\n", "lights:\n" + ENV.format(path=path)), frag, 0 if frag == "OK" else 2)
# --- a mesh file's own materials and structure ------------------------------------------------------
OWN = "  - name: thing\n    mesh: {path}\n"  # rendered with the file's own materials (no `material:`)
case("mtl_texture_garbage_png", sub("lights:", OWN.format(path="mtl_bad.obj") + "lights:"), "could not decode it")
case("mtl_texture_replaced_ok", sub("lights:", MESH.format(path="mtl_bad.obj") + "lights:"), "OK", 0)  # not read
case("gltf_nested_100000", sub("lights:", MESH.format(path="deep.gltf") + "lights:"), "nested too deeply")
case("gltf_node_chain_100000", sub("lights:", MESH.format(path="chain.gltf") + "lights:"),
     "nodes are nested more than 1024 levels deep")
case("gltf_node_cycle", sub("lights:", MESH.format(path="cycle.gltf") + "lights:"), "a node is its own ancestor")
# --- sequences: what a sequence can give, and numbers derived from the spec's (issue 25) -------------
SEQ_VIEWS = sub("    orbit: {center: [0, 0, 0], radius_m: 2.0, elevations_deg: [30], count: 3}",
                "    trajectory: {keyframes: [{time_s: 0, eye: [0, -2, 1.5], target: [0, 0, 0]}]}")


def sequence(section: str):
    return lambda text: SEQ_VIEWS(text) + f"sequence: {section}\n"


case("sequence_ok", sequence("{fps: 20, frames: 5, flow_steps: [1, 4], tracks: {count: 100}}"), "OK", 0)
case("flow_steps_50", sequence("{fps: 20, frames: 5, flow_steps: [50]}"), "expected a step below 5")
case("flow_steps_1e12", sequence("{fps: 20, frames: 5, flow_steps: [1, 1000000000000]}"), "flow_steps[1]: expected a step below 5")
case("flow_steps_5", sequence("{fps: 20, frames: 5, flow_steps: [5]}"), "expected a step below 5")
# one frame and the default flow step (1): no pair to make, no flow (it was a traceback)
case("single_frame_default_steps", sequence("{fps: 10, frames: 1}"), "OK", 0)
case("single_frame_step_1", sequence("{fps: 10, frames: 1, flow_steps: [1]}"), "flow_steps[0]: expected a step below 1")
case("tracks_count_1e9", sequence("{fps: 20, frames: 5, tracks: {count: 1000000000}}"), "<= 1000000")
case("tracks_count_pixels", sequence("{fps: 20, frames: 5, tracks: {count: 10000}}"), "expected at most 3,072 query points")
case("fps_1e-320", sequence("{fps: 1e-320, frames: 5}"), "sequence.timestamps_s[1]: expected a finite number, got inf")
case("start_s_overflow", sequence("{fps: 1e-308, frames: 5, start_s: 1.7e308}"), "expected a finite number, got inf")
# --- sizes of the file itself ---------------------------------------------------------------------
case("spec_50mb", append("# " + "x" * (50 * 2**20) + "\n"), "at most 1 MiB are read")
case("spec_2mb_comment", append("# " + "x" * (2 * 2**20) + "\n"), "at most 1 MiB are read")
case("many_look_ats_ok", sub("    orbit: {center: [0, 0, 0], radius_m: 2.0, elevations_deg: [30], count: 3}",
                             "    look_at:\n" + "".join(f"      - {{eye: [{2 + i * 0.01:.2f}, 0.5, 1], target: [0, 0, 0]}}\n"
                                                      for i in range(200))), "OK", 0)


def write_assets(d) -> None:
    """The files the cases name, next to the spec."""
    (d / "nan.obj").write_text("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    (d / "range.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    (d / "nofaces.obj").write_text("v 0 0 0\nv 1 0 0\n")
    (d / "garbage.ply").write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 99999999\n"
                                    b"property float x\nend_header\n\x00\x01")
    (d / "empty.obj").write_bytes(b"")
    (d / "mesh.txt").write_text("v 0 0 0\n")
    (d / "dir.obj").mkdir(exist_ok=True)
    (d / "dir.png").mkdir(exist_ok=True)
    (d / "empty.png").write_bytes(b"")
    (d / "corrupt.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(200)))
    png = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x00\x10\x00\x00\x00\x10\x08\x02\x00\x00\x00\x90\x91h6"
    (d / "truncated.png").write_bytes(png + b"\x00\x00\x01\x00IDAT")
    hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"
    (d / "text.exr").write_text("hello, not an EXR file\n")
    (d / "empty.hdr").write_bytes(b"")
    (d / "wide.hdr").write_bytes(hdr + b"-Y 1 +X 100000\n" + bytes(16))
    (d / "huge.hdr").write_bytes(hdr + b"-Y 100000 +X 100000\n" + bytes(16))
    (d / "noheader.hdr").write_bytes(b"P6\n4 4\n255\n" + bytes(48))
    (d / "env.tif").write_bytes(b"II*\x00")
    (d / "dir.exr").mkdir(exist_ok=True)
    rgb = np.linspace(0, 1, 8 * 16 * 3, dtype=np.float32).reshape(8, 16, 3)
    assert cv2.imwrite(str(d / "ok.hdr"), rgb)
    write_exr(d / "ok.exr", pack_channels("", rgb, "RGB"))
    write_exr(d / "uv.exr", pack_channels("", rgb[..., :2], "UV"))
    rgb[3, 4, 1] = np.nan
    write_exr(d / "nan.exr", pack_channels("", rgb, "RGB"))
    (d / "mtl_bad.obj").write_text("mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                   "usemtl a\nf 1/1 2/2 3/3\n")
    (d / "bad.mtl").write_text("newmtl a\nKd 1 1 1\nmap_Kd corrupt.png\n")
    (d / "deep.gltf").write_text('{"asset": {"version": "2.0"}, "extras": ' + "[" * 100_000 + "]" * 100_000 + "}")
    tri = {"meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
           "bufferViews": [{"buffer": 0, "byteLength": 36}],
           "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64," + "A" * 48}]}
    chain = [{"children": [i + 1]} for i in range(99_999)] + [{"mesh": 0}]
    for name, nodes in [("chain", chain), ("cycle", [{"children": [1], "mesh": 0}, {"children": [0]}])]:
        (d / f"{name}.gltf").write_text(json.dumps({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                                                    "nodes": nodes, **tri}))
