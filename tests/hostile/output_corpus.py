"""The malformed estimator-output corpus (issue 18): each case writes one estimate (or truth, or
gate, or task) file next to good ones, runs a ``recon-eval`` command on it and names the
message fragment and exit code it must give. tests/hostile/test_hostile_output_corpus.py runs
every case through ``recon_eval.cli.main``."""
from __future__ import annotations

import io
import json
import sys
import zipfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import good_tracks  # noqa: E402

from scenegen.dataset.codecs import TRACK_KEYS, encode_exr, encode_png  # noqa: E402

ROT = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
GOOD_POSE = {"R": ROT, "t": [0.1, 0.2, 3.0]}
H_GOOD = "1 0.01 2\n0.02 1 -3\n0.0001 0 1\n"
DEEP_JSON = "[" * 100_000 + "]" * 100_000
UTF16 = "1 0 0\n".encode("utf-16")
BINARY = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\xff"
TRUNCATED_EXR = encode_exr({"depth_z": np.full((6, 8), 2.0, np.float32)})[:-10]  # OpenEXR prints to stdout and stderr
TRUNCATED_PNG = encode_png(np.full((6, 8), 512, np.uint16))[:-5]  # libpng prints "libpng error: ..."


def npy_bytes(a) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a, allow_pickle=True)
    return buf.getvalue()


#: (case id, command: "pnp" | "homography" | "poses" | "depth" | "calibration" | "gate" | "fmatrix",
#:  file name, content (str, bytes or a JSON-able object; None: a directory), fragment, exit code)
CASES: list = []


def case(cid, command, name, content, fragment, code=2, extra=()):
    CASES.append((cid, command, name, content, fragment, code, tuple(extra)))


# --- pnp: one pose (.json / .txt / .npy) -----------------------------------------------------------
J = "pose.json"
case("pnp_ok", "pnp", J, GOOD_POSE, "trans_rel_err", 0)
case("pnp_nan_is_a_failure", "pnp", J, {"R": [[float("nan")] * 3] * 3, "t": [0, 0, 0]}, '"failed": true', 0)
case("pnp_invalid_json", "pnp", J, "{R: 1", "invalid JSON")
case("pnp_deep_json", "pnp", J, DEEP_JSON, "invalid JSON")
case("pnp_deep_object", "pnp", J, '{"R":' * 50_000 + "1" + "}" * 50_000, "invalid JSON")
case("pnp_empty_json", "pnp", J, "", "invalid JSON")
case("pnp_utf16", "pnp", J, json.dumps(GOOD_POSE).encode("utf-16"), "not a UTF-8 text file")
case("pnp_binary", "pnp", J, BINARY, "not a UTF-8 text file")
case("pnp_null", "pnp", J, "null", "expected a 3x4 or 4x4 pose matrix (12 or 16 numbers), got 1")
case("pnp_string", "pnp", J, '"R"', "R, t: expected numbers")
case("pnp_missing_t", "pnp", J, {"R": ROT}, "expected fields R (3x3) and t (3)")
case("pnp_R_2x2", "pnp", J, {"R": [[1, 0], [0, 1]], "t": [0, 0, 0]}, "R must be 3x3")
case("pnp_t_2", "pnp", J, {"R": ROT, "t": [0, 0]}, "R must be 3x3 and t 3 numbers")
case("pnp_R_text", "pnp", J, {"R": [["a", 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 0]}, "expected numbers")
case("pnp_R_ragged", "pnp", J, {"R": [[1, 0, 0], [0, 1], [0, 0, 1]], "t": [0, 0, 0]}, "expected numbers")
case("pnp_R_scaled", "pnp", J, {"R": [[2, 0, 0], [0, 2, 0], [0, 0, 2]], "t": [0, 0, 0]}, "R is not a rotation")
case("pnp_R_reflection", "pnp", J, {"R": [[1, 0, 0], [0, 1, 0], [0, 0, -1]], "t": [0, 0, 0]}, "R is not a rotation")
case("pnp_R_shear", "pnp", J, {"R": [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 0]}, "R is not a rotation")
case("pnp_R_zero", "pnp", J, {"R": [[0] * 3] * 3, "t": [0, 0, 0]}, "R is not a rotation")
case("pnp_R_rounded_3_digits", "pnp", J, {"R": [[0.707, -0.707, 0], [0.707, 0.707, 0], [0, 0, 1]], "t": [0, 0, 0]},
     "R is not a rotation")
case("pnp_4x4_bad_row", "pnp", J, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]], "must end with the row 0 0 0 1")
case("pnp_matrix_10", "pnp", J, list(range(10)), "12 or 16 numbers")
case("pnp_wf_key", "pnp", J, {"world_from_cam": {"R": [[3, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 0]}},
     "R is not a rotation")
T = "pose.txt"
case("pnp_txt_11", "pnp", T, "1 0 0 0 0 1 0 0 0 0 1\n", "expected a 3x4 or 4x4 pose matrix")
case("pnp_txt_words", "pnp", T, "one two three\n", "expected 12 or 16 numbers")
case("pnp_txt_empty", "pnp", T, "", "expected a 3x4 or 4x4 pose matrix")
case("pnp_txt_not_rotation", "pnp", T, "1 0 0 0 0 1 0 0 0 0 5 0\n", "R is not a rotation")
case("pnp_txt_utf16", "pnp", T, UTF16, "not a UTF-8 text file")
N = "pose.npy"
case("pnp_npy_garbage", "pnp", N, b"\x93NUMPY garbage", "not a readable .npy array")
case("pnp_npy_text", "pnp", N, "1 0 0 0\n", "not a readable .npy array")
case("pnp_npy_shape", "pnp", N, npy_bytes(np.eye(2)), "12 or 16 numbers")
case("pnp_npy_pickle", "pnp", N, npy_bytes(np.array([{"R": 1}], dtype=object)), "not a readable .npy array")
case("pnp_npy_strings", "pnp", N, npy_bytes(np.array(["a", "b"])), "expected a numeric array")
case("pnp_duplicate_R", "pnp", J, '{"R": [[1,0,0],[0,1,0],[0,0,1]], "R": [[0,-1,0],[1,0,0],[0,0,1]], "t": [0,0,1]}',
     "duplicate key 'R' in a camera pose")
case("pnp_directory", "pnp", J, None, "no such file")
case("pnp_missing", "pnp", "absent.json", "<absent>", "no such file")
# --- homography: a 3x3 matrix, estimate or truth -----------------------------------------------------
case("h_ok", "homography", "h.txt", H_GOOD, "mace", 0)
case("h_degenerate_estimate_is_a_failure", "homography", "h.txt", "0 0 0\n0 0 0\n0 0 0\n", "inf", 0)
case("h_8_numbers", "homography", "h.txt", "1 0 0 0 1 0 0 0\n", "expected a 3x3 matrix (9 numbers), got 8")
case("h_10_numbers", "homography", "h.txt", "1 0 0 0 1 0 0 0 1 5\n", "got 10")
case("h_words", "homography", "h.txt", "a b c\n", "expected 9 numbers")
case("h_empty", "homography", "h.txt", "", "got 0")
case("h_utf16", "homography", "h.txt", UTF16, "not a UTF-8 text file")
case("h_binary", "homography", "h.txt", BINARY, "not a UTF-8 text file")
case("h_json_no_key", "homography", "h.json", {"F": np.eye(3).tolist()}, "an object with key 'H'")
case("h_json_deep", "homography", "h.json", DEEP_JSON, "invalid JSON")
case("h_json_invalid", "homography", "h.json", "[[1, 0", "invalid JSON")
case("h_json_duplicate", "homography", "h.json", '{"H": [[1,0,0],[0,1,0],[0,0,1]], "H": [[2,0,0],[0,1,0],[0,0,1]]}',
     "duplicate key 'H' in a 3x3 matrix")
case("h_json_ragged", "homography", "h.json", [[1, 0, 0], [0, 1], [0, 0, 1]], "expected a 3x3 array of numbers")
case("h_json_strings", "homography", "h.json", [["x"] * 3] * 3, "expected a 3x3 array of numbers")
case("h_npy_shape", "homography", "h.npy", npy_bytes(np.eye(4)), "expected an array of shape (3, 3)")
case("h_npy_garbage", "homography", "h.npy", b"not npy", "not a readable .npy array")
case("h_directory", "homography", "h.txt", None, "no such file")
case("h_gt_singular", "homography", "gt.txt", "1 0 0\n0 1 0\n0 0 0\n", "gt.txt: the truth H is degenerate")
case("h_gt_zero", "homography", "gt.txt", "0 0 0\n0 0 0\n0 0 0\n", "gt.txt: the truth H is degenerate")
case("h_gt_nan", "homography", "gt.txt", "nan 0 0\n0 1 0\n0 0 1\n", "gt.txt: the truth H is degenerate")
case("h_size_negative", "homography", "h.txt", H_GOOD, "--size: expected the image width and height", 2,
     ("--size", "-80", "0"))
case("h_size_zero", "homography", "h.txt", H_GOOD, "two numbers >= 1", 2, ("--size", "0", "60"))
case("h_size_text", "homography", "h.txt", H_GOOD, "invalid int value", 2, ("--size", "wide", "60"))
# --- poses: TUM and KITTI trajectories ------------------------------------------------------------
TUM_OK = "".join(f"{i:.1f} {i * 0.1} {i * i * 0.05} {1 + (i % 2) * 0.2} 0 0 0 1\n" for i in range(6))
case("tum_ok", "poses", "est.txt", TUM_OK, "ape", 0)
case("tum_7_columns", "poses", "est.txt", "0.0 0 0 1 0 0 0\n", "expected 8 (TUM) or 12 (KITTI odometry) numbers per line, got 7")
case("tum_words", "poses", "est.txt", "0.0 a b c d e f g\n", "not numbers")
case("tum_nan", "poses", "est.txt", "0.0 nan 0 1 0 0 0 1\n1.0 0 0 1 0 0 0 1\n", "non-finite values or zero quaternions")
case("tum_zero_quaternion", "poses", "est.txt", "0.0 0 0 1 0 0 0 0\n1.0 0 0 1 0 0 0 1\n", "non-finite values or zero quaternions")
case("tum_empty", "poses", "est.txt", "", "empty trajectory")
case("tum_comments_only", "poses", "est.txt", "# timestamp tx ty tz qx qy qz qw\n", "empty trajectory")
case("tum_utf16", "poses", "est.txt", TUM_OK.encode("utf-16"), "not a UTF-8 text file")
case("tum_binary", "poses", "est.txt", BINARY, "not a UTF-8 text file")
case("kitti_11", "poses", "est.txt", "1 0 0 0 0 1 0 0 0 0 1\n", "got 11")
case("kitti_not_rotation", "poses", "est.txt", "2 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 0\n", "R is not a rotation")
case("poses_directory_not_a_model", "poses", "est", None, "folder is neither a dataset")
# --- depth: .npy maps -------------------------------------------------------------------------------
case("depth_ok", "depth", "d.npy", npy_bytes(np.full((6, 8), 2.0)), "abs_rel", 0)
case("depth_shape", "depth", "d.npy", npy_bytes(np.ones((5, 8))), "shape (5, 8) differs from the truth's (6, 8)")
case("depth_3d", "depth", "d.npy", npy_bytes(np.ones((6, 8, 3))), "got (6, 8, 3)")
case("depth_strings", "depth", "d.npy", npy_bytes(np.array([["a"] * 8] * 6)), "expected a numeric array")
case("depth_pickle", "depth", "d.npy", npy_bytes(np.array([None] * 48, dtype=object).reshape(6, 8)),
     "not a readable .npy array")
case("depth_garbage", "depth", "d.npy", b"\x93NUMPY\x01\x00garbage", "not a readable .npy array")
case("depth_empty_file", "depth", "d.npy", b"", "not a readable .npy array")
case("depth_pfm_garbage", "depth", "d.pfm", b"PF\nx y\n-1\n", "not a PFM file")
case("depth_exr_garbage", "depth", "d.exr", b"v/1\x01garbage", "not a readable EXR file")
case("depth_unknown_suffix", "depth", "d.bmp", b"BM", "unknown image format '.bmp'")
# --- calibration: OpenCV YAML / JSON ------------------------------------------------------------------
CAL = "%YAML:1.0\n---\nimage_width: 80\nimage_height: 60\ncamera_matrix: !!opencv-matrix\n  rows: 3\n  cols: 3\n" \
      "  dt: d\n  data: [70, 0, 40, 0, 70, 30, 0, 0, 1]\n{d}"
DIST = "distortion_coefficients: !!opencv-matrix\n  rows: 1\n  cols: {n}\n  dt: d\n  data: [{v}]\n"
case("calib_ok", "calibration", "est.yaml", CAL.format(d=""), "fx", 0)
case("calib_dist_7", "calibration", "est.yaml", CAL.format(d=DIST.format(n=7, v="0, 0, 0, 0, 0, 0, 0")),
     "opencv distortion needs 4, 5, 8, 12")
case("calib_dist_7_nonzero", "calibration", "est.yaml", CAL.format(d=DIST.format(n=7, v="0.1, 0, 0, 0, 0, 0, 0")),
     "got 7")
case("calib_dist_3", "calibration", "est.yaml", CAL.format(d=DIST.format(n=3, v="0.1, 0, 0")), "got 3")
case("calib_K_8", "calibration", "est.yaml", CAL.format(d="").replace("rows: 3\n  cols: 3", "rows: 1\n  cols: 8")
     .replace("0, 0, 1]", "0, 0]"), "expected 9 numbers")
case("calib_K_lower", "calibration", "est.yaml", CAL.format(d="").replace("70, 0, 40, 0, 70, 30, 0, 0, 1",
                                                                          "70, 0, 40, 0, 70, 30, 5, 0, 1"),
     "upper-triangular")
case("calib_no_K", "calibration", "est.yaml", "%YAML:1.0\n---\nimage_width: 80\n", "no camera matrix")
case("calib_no_size", "calibration", "est.yaml", CAL.format(d="").replace("image_width: 80\nimage_height: 60\n", ""),
     "no image size")
case("calib_negative_size", "calibration", "est.yaml", CAL.format(d="").replace("image_width: 80", "image_width: -80"),
     "expected positive integers")
case("calib_garbage", "calibration", "est.yaml", "%YAML:1.0\n---\n: : :\n", "not a readable OpenCV YAML/JSON file")
case("calib_utf16", "calibration", "est.yaml", CAL.format(d="").encode("utf-16"), "not a UTF-8 text file")
case("calib_binary", "calibration", "est.yaml", BINARY, "not a UTF-8 text file")
case("calib_json_deep", "calibration", "est.json", DEEP_JSON, "nested deeper than 64 levels")
case("calib_duplicate_matrix", "calibration", "est.yaml", CAL.format(d="") + CAL.format(d="").split("---\n")[1]
     .split("image_height: 60\n")[1], "duplicate key 'camera_matrix' (first given at line 5)")
case("calib_duplicate_width", "calibration", "est.yaml", CAL.format(d="").replace("image_height: 60", "image_height: 60\n"
     "image_width: 800"), "duplicate key 'image_width' (first given at line 3)")
case("calib_duplicate_json", "calibration", "est.json", '{"image_width": 80, "image_width": 90}', "duplicate key 'image_width'")
case("calib_missing", "calibration", "absent.yaml", "<absent>", "no such file")
# --- gate files (YAML through scenegen.located_yaml) ----------------------------------------------------
G = "version: 1\ngates:\n  - method: m\n    metric: rmse_m\n    op: '<='\n    threshold: 0.1\n"
case("gate_duplicate_threshold", "gate", "gate.yaml", G + "    threshold: 100\n", "duplicate key 'threshold'")
case("gate_duplicate_gates", "gate", "gate.yaml", G + "gates: []\n", "duplicate key 'gates'")
case("gate_unknown_key", "gate", "gate.yaml", G + "    treshold: 1\n", "unknown key 'treshold'")
case("gate_bad_op", "gate", "gate.yaml", G.replace("'<='", "'=<'"), "expected one of")
case("gate_nan", "gate", "gate.yaml", G.replace("0.1", ".nan"), "expected a finite number")
case("gate_text", "gate", "gate.yaml", G.replace("0.1", "small"), "expected a finite number")
case("gate_version", "gate", "gate.yaml", G.replace("version: 1", "version: 2"), "expected 1")
case("gate_empty_list", "gate", "gate.yaml", "version: 1\ngates: []\n", "non-empty list of gates")
case("gate_python_tag", "gate", "gate.yaml", G.replace("rmse_m", "!!python/name:os.system rmse_m"), "is not allowed")
case("gate_alias_bomb", "gate", "gate.yaml", G + "".join(
    f"x{i}: &x{i} [" + ", ".join([f"*x{i - 1}"] * 9 if i else ["1"] * 9) + "]\n" for i in range(9)), "aliases")
case("gate_utf16", "gate", "gate.yaml", G.encode("utf-16"), "UTF-16 encoded")
case("gate_directory", "gate", "gate.yaml", None, "is a directory")
case("gate_results_deep_json", "gate", "result.json", DEEP_JSON, "nested too deeply")
case("gate_results_invalid", "gate", "result.json", "{", "invalid JSON")
# --- issue 25: sizes declared in NPY headers, truth tracks, .flo, images and EXRs through C libraries --
def npy_header(shape, descr="<f4") -> bytes:
    """An NPY file that is only a header: it declares ``shape`` and holds no data."""
    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False, "shape": shape})
    return buf.getvalue()


def npz_bytes(members: dict, compression=zipfile.ZIP_STORED) -> bytes:
    """An NPZ of ``{member name: bytes}``, written member by member (headers may lie)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=compression) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return buf.getvalue()


def tracks_npz(tracks_xy, occluded) -> bytes:
    return npz_bytes({"tracks_xy.npy": npy_bytes(np.asarray(tracks_xy)), "occluded.npy": npy_bytes(np.asarray(occluded))})


GOOD_TRACKS = good_tracks()
OCC = npy_bytes(GOOD_TRACKS.occluded)
BOMB = npy_header((20_000_000_000,))  # 74.5 GiB of float32 declared in 128 bytes
case("tracks_ok", "tracks", "pred.npz", tracks_npz(GOOD_TRACKS.tracks_xy, GOOD_TRACKS.occluded), "average_jaccard", 0)
case("tracks_npz_header_claims_74_gib", "tracks", "pred.npz", npz_bytes({"tracks_xy.npy": BOMB, "occluded.npy": OCC}),
     "member 'tracks_xy.npy': the header declares shape (20000000000,) of float32 (80,000,000,000 bytes), but the "
     "file holds 0 bytes")
case("tracks_npz_deflated_header_claims_74_gib", "tracks", "pred.npz",
     npz_bytes({"tracks_xy.npy": BOMB, "occluded.npy": OCC}, zipfile.ZIP_DEFLATED), "(80,000,000,000 bytes)")
case("tracks_npz_header_within_file_over_limit", "tracks", "pred.npz",
     npz_bytes({"tracks_xy.npy": npy_header((3, 2, 2**30))}), "at most 4 GiB")
case("tracks_npz_header_longer_than_data", "tracks", "pred.npz",
     npz_bytes({"tracks_xy.npy": npy_bytes(np.zeros((3, 2, 2), np.float32))[:-8], "occluded.npy": OCC}),
     "(48 bytes), but the file holds 40 bytes")
case("tracks_npz_negative_shape", "tracks", "pred.npz", npz_bytes({"tracks_xy.npy": npy_header((-1, 2, 2))}),
     "expected non-negative dimensions")
case("tracks_npz_pickle", "tracks", "pred.npz", npz_bytes({"tracks_xy.npy": npy_bytes(np.array([{}], dtype=object))}),
     "an object array (it needs pickle")
case("tracks_npz_not_npy_member", "tracks", "pred.npz", npz_bytes({"tracks_xy.txt": b"1 2"}),
     "expected members with distinct names <key>.npy")
case("tracks_npz_duplicate_member", "tracks", "pred.npz",
     npz_bytes({"tracks_xy.npy": npy_bytes(GOOD_TRACKS.tracks_xy), "occluded.npy": OCC, "tracks_xy.np_": OCC})
     .replace(b"tracks_xy.np_", b"tracks_xy.npy"),
     "expected members with distinct names <key>.npy")
case("tracks_shape", "tracks", "pred.npz", tracks_npz(GOOD_TRACKS.tracks_xy[:, :1], GOOD_TRACKS.occluded),
     "tracks_xy: expected numbers of shape (3, 2, 2)")
case("tracks_not_a_zip", "tracks", "pred.npz", BINARY, "not a readable pickle-free .npz of tracks")
case("tracks_truth_nan_where_visible", "tracks_truth", "truth.npz", npz_bytes({
    f"{k}.npy": npy_bytes(np.full_like(GOOD_TRACKS.tracks_xy, np.nan) if k == "tracks_xy" else getattr(GOOD_TRACKS, k))
    for k in TRACK_KEYS}),
     "tracks: tracks_xy: track 0 at frame 0 is visible (not occluded) but not finite")
case("depth_npy_header_claims_74_gib", "depth", "d.npy", BOMB, "the header declares shape (20000000000,) of float32")
case("depth_exr_truncated", "depth", "d.exr", TRUNCATED_EXR, "not a readable EXR file")
case("depth_png_truncated", "depth", "d.png", TRUNCATED_PNG, "not a readable PNG")
FLO_HEAD = np.array([202021.25], "<f4").tobytes() + np.array([4, 3], "<i4").tobytes()
case("flow_ok", "flow", "f.flo", FLO_HEAD + np.zeros(24, "<f4").tobytes(), "epe", 0)
case("flow_flo_magic", "flow", "f.flo", b"\x00" * 20,
     "not a .flo file (magic 0, bytes b'\\x00\\x00\\x00\\x00'; expected 202021.25, bytes b'PIEH')")
case("flow_flo_truncated", "flow", "f.flo", FLO_HEAD + b"\x00" * 8,
     "expected sizes >= 1 and 12 + 8 * W * H = 108 bytes")
case("flow_flo_short", "flow", "f.flo", b"PIEH", "expected a 12-byte header")
case("flow_flo_huge_size", "flow", "f.flo", FLO_HEAD[:4] + np.array([2**31 - 1] * 2, "<i4").tobytes(),
     "a .flo header of width 2147483647 and height 2147483647")
case("flow_png_truncated", "flow", "f.png", TRUNCATED_PNG, "not a readable PNG")
# --- run: a user's estimator (--command, --methods-file); FILE is the case's file, DS the dataset ----
RUN = ("--kind", "sfm", "DS", "-o", "RUNS")
EXIT_1 = "import sys; sys.exit(1)\n"
case("run_timeout_zero", "run", "est.py", EXIT_1, "--timeout: expected a finite number of seconds > 0, got 0.0", 2,
     ("--command", "{python} FILE {images} {out}", "--timeout", "0", *RUN))
case("run_timeout_nan", "run", "est.py", EXIT_1, "--timeout: expected a finite number of seconds > 0, got nan", 2,
     ("--command", "{python} FILE {images} {out}", "--timeout", "nan", *RUN))
case("run_timeout_inf", "run", "est.py", EXIT_1, "--timeout: expected a finite number of seconds > 0, got inf", 2,
     ("--command", "{python} FILE {images} {out}", "--timeout", "inf", *RUN))
case("run_name_path", "run", "est.py", EXIT_1, "--name: '../x': expected 1-128 letters, digits", 2,
     ("--command", "{python} FILE {images} {out}", "--name", "../x", *RUN))
case("run_name_builtin", "run", "est.py", EXIT_1, "--name: 'opencv-f-8point' is a built-in method", 2,
     ("--command", "{python} FILE {images} {out}", "--name", "opencv-f-8point", *RUN))
case("run_command_no_out", "run", "est.py", EXIT_1, "--command: needs {out}", 2, ("--command", "{python} FILE", *RUN))
case("run_cannot_start", "run", "est.py", EXIT_1, "method 'my-est': cannot run '/nonexistent/prog'", 2,
     ("--command", "/nonexistent/prog FILE {images} {out}", "--name", "my-est", *RUN))
case("run_exit_status_names_the_method", "run", "est.py", EXIT_1, "recon-eval: my-est: sfm: exit status 1", 0,
     ("--command", "{python} FILE {images} {out}", "--name", "my-est", *RUN))
METHODS = "version: 1\nmethods:\n  - {name: filed, kind: sfm, command: '%s {images} {out}'%s}\n"
case("run_methods_file_cannot_start", "run", "m.yaml", METHODS % ("/nonexistent/prog", ""),
     "method 'filed': cannot run '/nonexistent/prog'", 2, ("filed", "DS", "-o", "RUNS", "--methods-file", "FILE"))
case("run_methods_file_timeout_zero", "run", "m.yaml", METHODS % ("false", ", timeout_s: 0"),
     "m.yaml:3: methods[0].timeout_s: expected a finite number of seconds > 0, got 0", 2,
     ("filed", "DS", "-o", "RUNS", "--methods-file", "FILE"))
case("run_methods_file_exit_status", "run", "m.yaml", METHODS % ("false", ""), "recon-eval: filed: sfm: exit status 1",
     0, ("filed", "DS", "-o", "RUNS", "--methods-file", "FILE"))
case("run_methods_file_timeout_nan", "run", "m.yaml", METHODS % ("false", ", timeout_s: .nan"),
     "m.yaml:3: methods[0].timeout_s: expected a finite number", 2,
     ("filed", "DS", "-o", "RUNS", "--methods-file", "FILE"))
