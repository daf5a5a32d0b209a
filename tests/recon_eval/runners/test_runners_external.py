"""External methods (recon_eval.runners.external, .declared): a user's command line run and
scored like a built-in method. No-render tests for the command contract and failures; render
tests run docs/ci.md's worked example verbatim on scenes/wide_baseline.yaml and show that an
external F on the match sets gets exactly the built-in opencv-f-ransac numbers."""
from __future__ import annotations

import json
import shlex
from pathlib import Path

import cv2
import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.errors import InputError
from recon_eval.runners import external, run_method, stereo
from recon_eval.runners.common import RunOutput
from recon_eval.runners.declared import external_method, load_methods
from scenegen.dataset.codecs import write_pfm

ROOT = Path(__file__).resolve().parents[3]


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


# --- the command contract -----------------------------------------------------------------------
@pytest.mark.parametrize("command, kind, expect", [
    ("tool {images} {out}", "nope", "kind: expected one of fmatrix, disparity"),
    ("tool {images} {oot}", "fmatrix", "unknown placeholder {oot} for kind 'fmatrix'"),
    ("tool {images}", "fmatrix", "needs {out}"),
    ("tool 'unclosed {out}", "fmatrix", "cannot split"),
    ("tool {matches} {image1} {out}", "fmatrix", "use {matches} or the images, not both"),
    ("tool {images} {out}", "disparity", "unknown placeholder {images} for kind 'disparity'"),
])
def test_bad_commands_are_refused_naming_the_declaration(command, kind, expect):
    with pytest.raises(InputError) as e:
        external.check_command(command, kind, "m.yaml:4")
    assert str(e.value).startswith("m.yaml:4: ") and expect in str(e.value)


def test_substitution_is_per_argument_without_a_shell(tmp_path):
    argv = external.check_command("t --a={image1} {images} '$(rm -rf x); echo' {out}", "fmatrix", "x")
    got = external.substitute(argv, {"image1": "/d/a b.png", "images": ["/d/a b.png", "/d/c.png"], "out": "/o/F.txt"})
    assert got == ["t", "--a=/d/a b.png", "/d/a b.png", "/d/c.png", "$(rm -rf x); echo", "/o/F.txt"]
    with pytest.raises(InputError, match="must be an argument of its own"):
        external.substitute(["x{images}"], {"images": ["a", "b"]})


def _script(tmp_path, body: str) -> str:
    f = tmp_path / "tool.py"
    f.write_text("import sys, pathlib, time\n" + body)
    return f"{{python}} {shlex.quote(str(f))}"


def test_argv_reaches_the_program_verbatim(tmp_path):
    cmd = _script(tmp_path, "pathlib.Path(sys.argv[-1]).write_text(repr(sys.argv[1:-1]))\n") + " '$(x);|' {view1} {out}"
    out = RunOutput()
    why = external.invoke({"command": cmd, "kind": "fmatrix", "name": "m"},
                          {"view1": "v a", "out": str(tmp_path / "o.txt")}, tmp_path / "log", "p", out)
    assert why is None and (tmp_path / "o.txt").read_text() == repr(["$(x);|", "v a"])


def test_failures_are_recorded_with_stderr_not_raised(tmp_path, capsys):
    cmd = _script(tmp_path, "print('line one', file=sys.stderr); print('it broke', file=sys.stderr); sys.exit(3)\n")
    out = RunOutput()
    why = external.invoke({"command": cmd + " {out}", "kind": "fmatrix", "name": "m"}, {"out": "x"},
                          tmp_path / "log", "a__b", out)
    assert why == "exit status 3" and out.notes["a__b"]["stderr_tail"] == ["line one", "it broke"]
    assert (tmp_path / "log" / "stderr.txt").read_text() == "line one\nit broke\n"
    assert "m: a__b: exit status 3: it broke" in capsys.readouterr().err
    slow = _script(tmp_path, "time.sleep(30)\n") + " {out}"
    why = external.invoke({"command": slow, "kind": "fmatrix", "name": "m", "timeout_s": 0.5}, {"out": "x"},
                          tmp_path / "log2", "a__b", out)
    assert why == "timed out after 0.5 s"
    with pytest.raises(InputError, match="cannot run 'no-such-program-xyz'"):
        external.invoke({"command": "no-such-program-xyz {out}", "kind": "fmatrix", "name": "m"}, {"out": "x"},
                        tmp_path / "log3", "a__b", out)


def test_methods_file_errors_name_file_and_line(tmp_path):
    f = tmp_path / "m.yaml"
    cases = {
        "version: 1\nmethods:\n  - {name: a, kind: fmatrix, command: 't {images} {out}', kind: disparity}\n":
            "m.yaml:3: methods[0].kind: duplicate key",
        "version: 1\nmethods:\n  - {name: a, kind: flux, command: 't {out}'}\n": "m.yaml:3: methods[0].kind",
        "version: 1\nmethods:\n  - {name: opencv-f-ransac, kind: fmatrix, command: 't {images} {out}'}\n":
            "is a built-in method",
        "version: 1\nmethods:\n  - {name: a, kind: fmatrix, command: 't {images}'}\n": "m.yaml:3: methods[0]: command: needs {out}",
        "version: 1\nmethods:\n  - {name: ../x, kind: fmatrix, command: 't {images} {out}'}\n": "m.yaml:3: methods[0]: name: '../x'",
        "version: 1\nmethods:\n  - {name: a, kind: fmatrix, command: 't {images} {out}', timeout_s: -1}\n":
            "m.yaml:3: methods[0].timeout_s",
        "version: 1\nmethods:\n  - {name: a, kind: fmatrix, command: 't {images} {out}'}\n"
        "  - {name: a, kind: fmatrix, command: 't {images} {out}'}\n": "m.yaml:4: methods[1]: name: 'a' is declared twice",
    }
    for text, expect in cases.items():
        f.write_text(text)
        with pytest.raises(InputError) as e:
            load_methods(f)
        assert expect in str(e.value), (text, str(e.value))
    assert set(load_methods(ROOT / "examples" / "methods.yaml")) == {"my-fmatrix", "my-fmatrix-transposed",
                                                                     "my-f-matches"}


def test_cli_usage_errors(plane_dataset, tmp_path, capsys):
    root = plane_dataset[0]
    code, _, err = run(["run", "--command", "t {images} {out}", root, "-o", tmp_path], capsys)
    assert code == 2 and "--command needs --kind" in err
    code, _, err = run(["run", "opencv-f-ransac", root, "-o", tmp_path, "--kind", "fmatrix"], capsys)
    assert code == 2 and "--kind and --pixels go with --command" in err
    code, _, err = run(["run", "--command", "t {images} {out}", "--kind", "fmatrix", "--name", "opencv-f-8point",
                        root, "-o", tmp_path], capsys)
    assert code == 2 and "is a built-in method" in err


# --- disparity kind: the built-in stereo scoring, with a stand-in dataset --------------------------
class _Frame:
    """One rectified frame on disk: a random texture, truth disparity SHIFT everywhere."""

    SHIFT = 6.0

    def __init__(self, root: Path):
        self.root = root
        rng = np.random.default_rng(1)
        self.images = [rng.integers(0, 256, (24, 32), dtype=np.uint8) for _ in range(2)]
        for side, im in zip(("left", "right"), self.images):
            cv2.imwrite(str(root / f"{side}.png"), im)
        self.disp = np.full((24, 32), self.SHIFT)

    def stereo_left_views(self):
        return ("cam_l",)

    def stereo_images(self, left):
        return tuple(self.images)

    def stereo_image_path(self, left, side):
        return self.root / f"{side}.png"

    def stereo_disparity(self, left):
        return self.disp

    def stereo_noc_mask(self, left):
        return np.ones(self.disp.shape, bool)


def test_external_disparity_is_scored_as_the_builtin(tmp_path):
    """The command writes the truth with 10 pixels 3 px off: Middlebury bad-2.0 is exactly 10 / 768."""
    frame = _Frame(tmp_path)
    d = frame.disp.copy()
    d[0, :10] += 3.0
    np.save(tmp_path / "answer.npy", d)
    tool = tmp_path / "tool.py"
    tool.write_text("import sys, numpy as np\nfrom scenegen.dataset.codecs import write_pfm\n"
                    f"assert sys.argv[1].endswith('left.png') and sys.argv[2].endswith('right.png')\n"
                    f"write_pfm(sys.argv[3], np.load({str(tmp_path / 'answer.npy')!r}))\n")
    m = external_method("my-stereo", "disparity", f"{{python}} {tool} {{left}} {{right}} {{out}}")
    res = external.disparity(frame, tmp_path / "run", dict(m.options))
    assert res.metrics["bad_2_0_noc_pct"] == pytest.approx(100 * 10 / 768, abs=1e-12)
    assert res.raw_files == ["disparity/cam_l.pfm"]
    write_pfm(tmp_path / "same.pfm", d)
    ref = stereo.run(frame, tmp_path / "ref", {}, compute=lambda ds, left, path, out: path.write_bytes(
        (tmp_path / "same.pfm").read_bytes()))
    assert ref.metrics == res.metrics
    bad = external_method("bad-stereo", "disparity", "{python} -c 'import sys; sys.exit(1)' {left} {out}")
    res = external.disparity(frame, tmp_path / "run2", dict(bad.options))
    assert res.notes["cam_l"]["failed"] == "exit status 1" and res.metrics["invalid_noc_pct"] == 100.0


def test_external_disparity_of_the_wrong_sign_is_hinted(tmp_path, capsys):
    """The command writes the negated truth: ~100 % bad, and a warning naming the method and frame."""
    frame = _Frame(tmp_path)
    np.save(tmp_path / "neg.npy", -frame.disp)
    tool = tmp_path / "neg.py"
    tool.write_text("import sys, numpy as np\nfrom scenegen.dataset.codecs import write_pfm\n"
                    f"write_pfm(sys.argv[1], np.load({str(tmp_path / 'neg.npy')!r}))\n")
    m = external_method("neg-stereo", "disparity", f"{{python}} {tool} {{out}}")
    res = external.disparity(frame, tmp_path / "run", dict(m.options))
    assert res.metrics["bad_2_0_noc_pct"] > 99.0
    assert len(res.warnings) == 1 and res.warnings[0].startswith("cam_l (non-occluded): ")
    assert "is its sign reversed?" in res.warnings[0]


# --- on a rendered scene ----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def wide(tmp_path_factory):
    from scenegen.pipeline.run import render_spec

    root = tmp_path_factory.mktemp("wide") / "wide"
    render_spec(ROOT / "scenes" / "wide_baseline.yaml", root, progress=False)
    return root


def _worked_example():
    text = (ROOT / "docs" / "ci.md").read_text()
    block = text.split("<!-- worked-example:start -->", 1)[1].split("<!-- worked-example:end -->", 1)[0]
    lines = [ln for ln in block.splitlines() if ln.startswith(("scenegen ", "recon-eval "))]
    assert lines[0] == "scenegen render scenes/wide_baseline.yaml -o out/wide"
    return lines[1:]


@pytest.mark.render
def test_docs_worked_example_runs_as_written(wide, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(ROOT)  # the methods file names examples/my_fmatrix.py from the repository root
    for line in _worked_example():
        cmd, _, comment = line.partition("#")
        expect = int(comment.split("exit")[1]) if "exit" in comment else 0
        argv = [str(wide) if t == "out/wide" else str(tmp_path / t) if t.startswith(("runs/", "board")) else t
                for t in shlex.split(cmd)[1:]]
        code, out, err = run(argv, capsys)
        assert code == expect, (line, out, err)
        if argv[0] == "gate" and expect == 0:
            assert "2 of 2 gates hold" in out
        if argv[0] == "gate" and expect == 1:
            assert "FAIL sampson_rms_px" in out and "my-fmatrix-transposed" in out
    mine = json.loads((tmp_path / "runs/my-fmatrix/result.json").read_text())
    assert mine["command"] == "run" and mine["inputs"]["method"] == "my-fmatrix"
    assert mine["inputs"]["scene"] == "wide_baseline"
    assert mine["inputs"]["raw_files"] == ["pair_0000__pair_0001/F.txt"]
    m = mine["metrics"]
    assert m["sampson_rms_px"] == pytest.approx(1.098, abs=5e-3) and m["pose_err_deg"] == pytest.approx(10.4, abs=0.05)
    assert json.loads((tmp_path / "runs/my-f/result.json").read_text())["metrics"] == m  # --command: same numbers
    board = json.loads((tmp_path / "board/leaderboard.json").read_text())
    assert [r["inputs"]["method"] for r in board["runs"]] == ["my-fmatrix", "my-f-matches", "opencv-f-ransac"]
    assert {r["inputs"]["task"] for r in board["runs"]} == {"fundamental matrix"}  # one table on the page
    # the estimate from the images shares its columns with OpenCV's (its SIFT set): ranked, not starred alone
    shared = {"sampson_rms_px", "pose_err_deg", "f_distance_px"}
    assert all(shared <= set(r["metrics"]) for r in board["runs"])
    page = (tmp_path / "board/leaderboard.html").read_text()
    assert page.count("<h2>fundamental matrix</h2>") == 1 and 'href="wide_baseline/my-fmatrix/report.html"' in page
    report = (tmp_path / "board/wide_baseline/my-fmatrix/report.html").read_text()
    assert "<h2>Summary</h2>" in report and "sampson_rms_px" in report
    # a broken threshold fails the gate (exit 1) and names the gate's file:line
    g = tmp_path / "broken.yaml"
    g.write_text((ROOT / "examples" / "gates_my_fmatrix.yaml").read_text().replace("threshold: 2.0", "threshold: 0.5"))
    code, out, _ = run(["gate", g, tmp_path / "board/leaderboard.json", "--junit", tmp_path / "j.xml"], capsys)
    assert code == 1 and f"FAIL sampson_rms_px = {m['sampson_rms_px']:.6g}, threshold <= 0.5" in out and f"{g}:5" in out


@pytest.mark.render
def test_external_f_on_match_sets_equals_the_builtin(wide, tmp_path):
    """The same cv2 call as opencv-f-ransac, as a user's script on {matches}: identical result groups."""
    tool = tmp_path / "ransac.py"
    tool.write_text("import sys, cv2, numpy as np\nm = np.load(sys.argv[1])\n"
                    "F, mask = cv2.findFundamentalMat(m[:, :2], m[:, 2:], cv2.FM_RANSAC, 3.0, 0.999, 10000)\n"
                    "np.savetxt(sys.argv[2], F)\nnp.save(sys.argv[3], mask.ravel() != 0)\n")
    (tmp_path / "m.yaml").write_text(f"version: 1\nmethods:\n  - {{name: my-ransac, kind: fmatrix, command: "
                                     f"'{{python}} {tool} {{matches}} {{out}} {{inliers}}'}}\n")
    mine = run_method("my-ransac", wide, tmp_path / "mine", declared=load_methods(tmp_path / "m.yaml"))
    ref = run_method("opencv-f-ransac", wide, tmp_path / "ref")
    assert mine["metrics"] == ref["metrics"] and mine["results"] == ref["results"]
    assert mine["inputs"]["method"] == "my-ransac" and mine["inputs"]["options"]["kind"] == "fmatrix"
    assert (tmp_path / "mine" / "pair_0000__pair_0001" / "synthetic" / "matches.npy").is_file()


@pytest.mark.render
def test_truth_F_is_the_stored_crossview_F(wide):
    from recon_eval.readers.scenegen_dataset import read_dataset
    from scenegen.geometry.twoview import fundamental

    ds = read_dataset(wide)
    F, source = ds.truth_fundamental("pair_0000", "pair_0001")
    assert source == "crossview/twoview/pair_0000/pair_0001.json"
    (c1, p1), (c2, p2) = ds.camera("pair_0000"), ds.camera("pair_0001")
    G = fundamental(c1.K, c2.K, p2 @ p1.inverse())
    assert np.allclose(F / np.linalg.norm(F), G / np.linalg.norm(G) * np.sign(np.sum(F * G)), atol=1e-12)


# --- sfm kind: a COLMAP model written by the command, scored as pycolmap-incremental -------------
def _colmap_text_model(d: Path, cams: dict, views, points) -> None:
    from scipy.spatial.transform import Rotation

    d.mkdir(parents=True)
    (d / "cameras.txt").write_text("1 PINHOLE 40 30 40 40 19.5 14.5\n")
    lines = []
    for k, v in enumerate(views, start=1):
        pose = cams[v][1]
        x, y, z, w = Rotation.from_matrix(pose.R).as_quat()
        lines += [f"{k} " + " ".join(repr(float(c)) for c in (w, x, y, z, *pose.t)) + f" 1 {v}.png", ""]
    (d / "images.txt").write_text("\n".join(lines) + "\n")
    (d / "points3D.txt").write_text("".join(f"{k} {p[0]!r} {p[1]!r} {p[2]!r} 0 0 0 0.5\n"
                                            for k, p in enumerate(points, start=1)))


def test_external_sfm_model_is_scored_as_pycolmap(plane_dataset, tmp_path):
    root, cams = plane_dataset
    pts = [(0.1, 0.2, 0.0), (-1.0, 0.5, 0.0), (0.7, -0.3, 0.0), (0.2, 0.2, 0.05)]  # the last 5 cm off the plane
    _colmap_text_model(tmp_path / "answer", cams, ["left_000", "right_000", "free_000"], pts)
    tool = tmp_path / "sfm.py"
    tool.write_text("import shutil, sys, pathlib\nassert sorted(p.name for p in pathlib.Path(sys.argv[1]).iterdir()) =="
                    " ['free_000.png', 'left_000.png', 'right_000.png']\n"
                    f"shutil.copytree({str(tmp_path / 'answer')!r}, sys.argv[2], dirs_exist_ok=True)\n")
    m = external_method("my-sfm", "sfm", f"{{python}} {tool} {{images}} {{out}}")
    assert m.task == "structure from motion"
    doc = run_method("my-sfm", root, tmp_path / "run", declared={"my-sfm": m})
    met = doc["metrics"]
    assert met["registration_ratio"] == 1.0 and met["max_rot_err_deg"] < 1e-6 and met["n_points3d"] == 4
    assert met["cloud_precision_at_1cm"] == 0.75
    # the same model scored by hand: the same numbers under the same names (one gate file for both)
    assert main(["poses", str(tmp_path / "run" / "model"), str(root), "--json", str(tmp_path / "p.json"), "-q"]) == 0
    by_hand = json.loads((tmp_path / "p.json").read_text())["metrics"]
    shared = ("registration_ratio", "max_rot_err_deg", "median_rot_err_deg")
    assert {k: by_hand[k] for k in shared} == {k: met[k] for k in shared}
    assert doc["inputs"]["raw_files"] == ["model/cameras.txt", "model/images.txt", "model/points3D.txt"]
    _colmap_text_model(tmp_path / "two", cams, ["left_000", "right_000"], pts)
    tool.write_text(f"import shutil, sys\nshutil.copytree({str(tmp_path / 'two')!r}, sys.argv[2], dirs_exist_ok=True)\n")
    doc = run_method("my-sfm", root, tmp_path / "run2", declared={"my-sfm": m})
    assert doc["metrics"]["max_rot_err_deg"] == "inf" and "registers 2 images" in doc["inputs"]["notes"]["failed"]
    tool.write_text("import sys\nsys.exit(4)\n")
    doc = run_method("my-sfm", root, tmp_path / "run3", declared={"my-sfm": m})
    assert doc["metrics"] == {"registration_ratio": 0.0, "max_rot_err_deg": "inf"}
    assert doc["inputs"]["notes"]["sfm"]["failed"] == "exit status 4"


def test_external_calibration_is_scored_as_the_builtin(plane_dataset, tmp_path):
    from recon_eval.readers.opencv_calib import write_opencv_calibration
    from scenegen.geometry.camera import Camera

    root, cams = plane_dataset
    for view, cam in (("left_000", "left"), ("right_000", "right"), ("free_000", "free")):
        c = cams[view][0]
        if cam == "free":  # the planted error: fx 0.5 px too long
            c = Camera(c.model, c.width, c.height, c.fx + 0.5, c.fy, c.cx, c.cy, 0.0, c.dist)
        write_opencv_calibration(tmp_path / f"{cam}.yaml", c)
    tool = tmp_path / "calib.py"
    tool.write_text("import shutil, sys, pathlib\nimages, cam, out = sys.argv[1:]\n"
                    "assert [p.name for p in pathlib.Path(images).iterdir()] == [cam + '_000.png']\n"
                    f"shutil.copy(pathlib.Path({str(tmp_path)!r}) / (cam + '.yaml'), out)\n")
    m = external_method("my-calib", "calibration", f"{{python}} {tool} {{images}} {{camera}} {{out}}")
    doc = run_method("my-calib", root, tmp_path / "run", declared={"my-calib": m})
    met = doc["metrics"]
    assert met["left.fx_rel_err"] == 0 and met["right.proj_diff_rms_px"] < 1e-9
    assert met["free.fx_rel_err"] == pytest.approx(0.5 / cams["free_000"][0].fx, abs=1e-15)
    assert "free.calib_rms_px" not in met and doc["inputs"]["task"] == "calibration"
    # the same file scored by hand: the run's names without the camera prefix, the same numbers
    assert main(["calibration", str(tmp_path / "run" / "calibration_free.yaml"), str(root), "--view", "free_000",
                 "--json", str(tmp_path / "c.json"), "-q"]) == 0
    by_hand = json.loads((tmp_path / "c.json").read_text())["metrics"]
    assert by_hand == {k.removeprefix("free."): v for k, v in met.items() if k.startswith("free.")}
    assert sorted(doc["inputs"]["raw_files"]) == ["calibration_free.yaml", "calibration_left.yaml",
                                                   "calibration_right.yaml"]


def test_leaderboard_with_declared_methods_and_gates(plane_dataset, tmp_path, capsys):
    """A methods file's method in `leaderboard`, gated there: exit 1 on a failed gate, the cell red,
    the run's report rewritten with its gate outcomes, the inapplicable built-in listed as skipped."""
    root, cams = plane_dataset
    _colmap_text_model(tmp_path / "answer", cams, ["left_000", "right_000", "free_000"], [(0.1, 0.2, 0.0)])
    tool = tmp_path / "sfm.py"
    tool.write_text(f"import shutil, sys\nshutil.copytree({str(tmp_path / 'answer')!r}, sys.argv[2], dirs_exist_ok=True)\n")
    (tmp_path / "m.yaml").write_text(f"version: 1\nmethods:\n  - {{name: my-sfm, kind: sfm, command: "
                                     f"'{{python}} {tool} {{images}} {{out}}'}}\n")
    (tmp_path / "g.yaml").write_text("version: 1\ngates:\n"
                                     "  - {method: 'my-*', metric: registration_ratio, op: '==', threshold: 1}\n"
                                     "  - {method: 'my-*', metric: n_points3d, op: '>=', threshold: 100}\n")
    code, out, err = run(["leaderboard", "--methods-file", tmp_path / "m.yaml", "--datasets", root, "--methods",
                          "my-sfm", "opencv-stereo-bm", "--gates", tmp_path / "g.yaml", "-o", tmp_path / "b"], capsys)
    assert code == 1, err
    assert "ok   registration_ratio = 1" in out and "FAIL n_points3d = 1, threshold >= 100" in out
    page = (tmp_path / "b" / "leaderboard.html").read_text()
    assert "<h2>structure from motion</h2>" in page and 'class="num best fail"' in page and 'class="num best pass"' in page
    assert "<h2>Skipped</h2>" in page and "opencv-stereo-bm" in page
    report = (tmp_path / "b" / json.loads((tmp_path / "b" / "leaderboard.json").read_text())["run_dirs"][0]
              / "report.html").read_text()
    assert "gate n_points3d &gt;= 100" in report and 'class="verdict fail"' in report
    # -q: the same files, and nothing printed but the failed gate (no run lines, no 'wrote')
    code, out, err = run(["-q", "leaderboard", "--methods-file", tmp_path / "m.yaml", "--datasets", root, "--methods",
                          "my-sfm", "opencv-stereo-bm", "--gates", tmp_path / "g.yaml", "-o", tmp_path / "q"], capsys)
    assert code == 1 and err == ""
    (line,) = out.splitlines()
    assert line.startswith("FAIL n_points3d = 1, threshold >= 100"), out
    assert (tmp_path / "q" / "leaderboard.html").is_file()


@pytest.mark.render
def test_external_homography_kind_on_the_planes(wide, tmp_path):
    """The truth H of each plane: MACE 0 under the built-in H methods' names; transposed: large."""
    est = ROOT / "tests" / "recon_eval" / "runners" / "estimators" / "true_homography.py"
    cmd = f"{{python}} {est} {{dataset}} {{view1}} {{view2}} {{plane}} {{out}}"
    doc = run_method("my-h", wide, tmp_path / "h", declared={"my-h": external_method("my-h", "homography", cmd)})
    ref = run_method("opencv-h-usac-magsac", wide, tmp_path / "ref")
    planes = {k for k in ref["metrics"] if not k.startswith("synthetic.")}  # the estimate from the images
    assert set(doc["metrics"]) >= planes and doc["inputs"]["task"] == ref["inputs"]["task"] == "homography"
    assert all(v < 1e-6 for v in doc["metrics"].values())
    bad = run_method("my-h-t", wide, tmp_path / "t",
                     declared={"my-h-t": external_method("my-h-t", "homography", cmd + " --transpose")})
    assert all(v > 10 for v in bad["metrics"].values())

