"""Issue 18, security: names read from a dataset or a task never reach a path unchecked; the
leaderboard neither escapes its output folder nor carries raw HTML; gate files refuse duplicate
keys. Each test crafts the hostile input an attacker can write (the manifest is re-signed, as
anyone can) and runs the real command."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from hostile_data import VIEWS, resign, run_cli, tree, write_dataset  # noqa: E402

from recon_eval.cli import main as recon_main  # noqa: E402
from recon_eval.report.leaderboard_page import html_page, markdown  # noqa: E402
from scenegen import dataset as ds  # noqa: E402
from scenegen.cli import main as scenegen_main  # noqa: E402

EVIL = "../../escape"


@pytest.fixture()
def dataset(tmp_path):
    root = tmp_path / "sandbox" / "ds"
    write_dataset(root)
    return root


def rename_view_in_cameras(root: Path, new: str) -> None:
    cams = json.loads((root / "cameras.json").read_text())
    old = cams["view_order"][0]
    cams["view_order"][0] = new
    cams["views"][new] = cams["views"].pop(old)
    (root / "cameras.json").write_text(json.dumps(cams))
    resign(root)


@pytest.mark.parametrize("fmt", ["colmap", "nerf", "opencv", "tum"])
def test_export_refuses_a_view_name_that_leaves_the_dataset_in_cameras_json(dataset, tmp_path, fmt):
    rename_view_in_cameras(dataset, EVIL)
    before = tree(tmp_path)
    code, _, err = run_cli(scenegen_main, ["export", dataset, "--format", fmt, "-o", tmp_path / "sandbox" / "out"])
    assert code == 2 and "cameras.json: lists an invalid view name" in err and "Traceback" not in err
    assert "'../../escape'" in err
    assert tree(tmp_path) == before  # nothing read from or written outside (nothing written at all)


def test_manifest_listing_a_path_outside_the_dataset_is_refused(dataset, tmp_path):
    def edit(m):
        entry = m["views"].pop(VIEWS[0])
        entry["files"] = [f.replace(VIEWS[0], EVIL) for f in entry["files"]]
        m["views"][EVIL] = entry
        for f in list(m["files"]):
            if VIEWS[0] in f:
                m["files"][f.replace(VIEWS[0], EVIL)] = m["files"].pop(f)
    resign(dataset, edit)
    with pytest.raises(ds.DatasetError, match="manifest.json: lists an invalid view name"):
        ds.Dataset(dataset)
    code, _, err = run_cli(scenegen_main, ["export", dataset, "--format", "colmap", "-o", tmp_path / "o"])
    assert code == 2 and "invalid view name" in err and not (tmp_path / "o").exists()


@pytest.mark.parametrize("key,entry", [("pairs", {"i": EVIL, "j": VIEWS[1]}),
                                       ("targets", EVIL), ("files", "crossview/../../x.exr")])
def test_crossview_index_names_are_checked_before_use(dataset, key, entry):
    from scenegen.dataset.crossview import CrossviewIndex
    doc = {"format": "scenegen-crossview-index", "format_version": 1, "pairs": [], "flow": [],
           "stereo": [], "targets": [], "files": []}
    from scenegen.dataset import crossview
    doc["format"], doc["format_version"] = crossview.INDEX_FORMAT, crossview.INDEX_FORMAT_VERSION
    doc[key].append(entry)
    with pytest.raises(ValueError, match="index: lists an invalid (view name|path)"):
        CrossviewIndex.from_dict(doc)


def test_triangulation_task_names_cannot_leave_the_task_folder(tmp_path):
    task = tmp_path / "task"
    task.mkdir()
    (tmp_path / "secret.txt").write_text("1 2 3 4\n")
    pair = {"name": "a__b", "n_points": 1, "files": {"P1": "../secret.txt", "P2": "a__b/P2.txt",
            "observations": "a__b/observations.txt", "truth": "truth/a__b.txt"},
            "cam1_from_world": {"R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 0]},
            "cam2_from_world": {"R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [1, 0, 0]}}
    from recon_eval.errors import InputError
    from recon_eval.tasks import triangulation_task as tt
    (task / "task.json").write_text(json.dumps({"format": tt.TASK_FORMAT, "version": tt.TASK_VERSION,
                                                "pairs": [pair]}))
    with pytest.raises(InputError, match=r"pairs\[0\].*'\.\./secret\.txt'"):
        tt.read_task(task)
    pair["files"]["P1"], pair["name"] = "a__b/P1.txt", "../../up"
    (task / "task.json").write_text(json.dumps({"format": tt.TASK_FORMAT, "version": tt.TASK_VERSION,
                                                "pairs": [pair]}))
    with pytest.raises(InputError, match=r"pairs\[0\].*pair name"):
        tt.read_task(task)


def test_leaderboard_does_not_use_a_crafted_scene_name_as_a_folder(dataset, tmp_path):
    cams = json.loads((dataset / "cameras.json").read_text())
    cams["spec"]["name"] = "../../lb_escape"
    (dataset / "cameras.json").write_text(json.dumps(cams))
    resign(dataset)
    out = tmp_path / "sandbox" / "lb"
    before = tree(tmp_path)
    code, _, err = run_cli(recon_main, ["leaderboard", "--datasets", dataset, "--methods", "opencv-features-orb",
                                        "-o", out])
    assert code == 2 and "scene name cannot be a folder name" in err and "'../../lb_escape'" in err
    assert tree(tmp_path) == before and not (tmp_path / "lb_escape").exists()


def test_leaderboard_pages_escape_names_and_messages():
    doc = {"runs": [{"inputs": {"scene": "<script>alert(1)</script>", "method": "m|x`y"},
                     "metrics": {"<img src=x onerror=alert(1)>": 1.0}}]}
    md = markdown(doc)
    assert "<script>" not in md and "<img" not in md and "&lt;script&gt;" in md
    row = md.splitlines()[2]
    assert row.count("|") - row.count("\\|") == 4  # the '|' of a name cannot add a column


def test_gate_file_with_a_duplicate_threshold_is_refused(tmp_path):
    from recon_eval.ci.gates import load_gates
    gate = tmp_path / "gate.yaml"
    gate.write_text("version: 1\ngates:\n  - method: m\n    metric: rmse_m\n    op: '<='\n"
                    "    threshold: 0.0001\n    threshold: 100\n")
    from scenegen.errors import SpecError
    from recon_eval.errors import InputError
    with pytest.raises((SpecError, InputError), match=r"gate\.yaml:7: .*duplicate key 'threshold' \(first given at line 6\)"):
        load_gates(gate)
    code, _, err = run_cli(recon_main, ["gate", gate, tmp_path / "result.json"])
    assert code == 2 and "gate.yaml:7: gates[0].threshold: duplicate key 'threshold'" in err


@pytest.mark.parametrize("payload,fragment", [
    (b"version: 1\ngates: !!python/name:os.system\n", "the YAML tag '!!python/name:os.system' is not allowed"),
    ("version: 1\n".encode("utf-16"), "UTF-16 encoded; save it as UTF-8"),
    (b"\x89PNG\r\n\x1a\n\x00\x00", "NUL byte (is this a binary file?)"),
    (b"version: 1\ngates: " + b"[" * 5000 + b"]" * 5000 + b"\n", "nesting deeper than 64 levels"),
])
def test_hostile_gate_files_fail_with_one_line(tmp_path, payload, fragment):
    gate = tmp_path / "gate.yaml"
    gate.write_bytes(payload)
    code, _, err = run_cli(recon_main, ["gate", gate, tmp_path / "result.json"])
    assert code == 2 and fragment in err and str(gate) in err and len(err.strip().splitlines()) == 1


def test_a_crafted_camera_name_cannot_name_a_file_outside(dataset):
    """Runners name files after a view's camera (calibration_<camera>.yaml): checked on read too."""
    cams = json.loads((dataset / "cameras.json").read_text())
    cams["views"][VIEWS[0]]["camera_name"] = "../../calib_escape"
    (dataset / "cameras.json").write_text(json.dumps(cams))
    resign(dataset)
    with pytest.raises(ds.DatasetError, match="cameras.json: lists an invalid camera name"):
        ds.Dataset(dataset).views_of_camera("cam0")


def test_leaderboard_html_escapes_names_metrics_and_reasons():
    doc = {"runs": [{"inputs": {"scene": "<script>alert(1)</script>", "method": "<b>m</b>"},
                     "metrics": {"<img src=x onerror=alert(1)>": 1.0}}],
           "skipped": [{"scene": "s", "method": "m", "why": "<script>alert(2)</script>"}]}
    page = html_page(doc)
    assert "<script>alert" not in page and "<img" not in page and "<b>m" not in page
    assert page.count("<script>") == 1  # the page's own sorting script, nothing else
