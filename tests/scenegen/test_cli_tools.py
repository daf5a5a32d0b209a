"""The command line's tools for a new user: progress on stderr counted in views (render and the
cross-view stage), no Mitsuba WARN lines, preview and gallery contact sheets, info --json."""
import html
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.export.sheet import GAP_PX, LABEL_PX, html_page, id_colours
from scenegen.pipeline.preview import scaled_camera
from scenegen.spec import load_spec, resolve_views

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.render

ENV = dict(os.environ, PYTHONPATH=str(ROOT), COLUMNS="120")  # this tree's scenegen in the subprocess
TINY = """
name: tiny
render: {spp: 1}
objects:
  - {name: floor, shape: {type: plane, size: [4, 4]}}
  - {name: ball, shape: {type: sphere, radius: 0.3}, transform: {translation: [0, 0, 0.3]}}
lights: [{type: constant, radiance: 0.5}]
cameras: {cam: {size: [64, 48], fov_deg: 60}}
views: [{camera: cam, orbit: {radius_m: 2, count: 3}}]
crossview: {pairs: consecutive, stereo: false}
"""


def test_render_progress_counts_views_on_stderr_without_mitsuba_warnings(tmp_path):
    (tmp_path / "tiny.yaml").write_text(TINY)
    r = subprocess.run([sys.executable, "-m", "scenegen.cli", "render", "tiny.yaml", "-o", "out"],
                       cwd=tmp_path, capture_output=True, text=True, env=ENV)
    assert r.returncode == 0, r.stderr
    # spp 1 with the ldsampler: Mitsuba used to log "WARN [LowDiscrepancySampler] ... rounding to 4"
    assert "WARN" not in r.stderr + r.stdout
    assert "views/s" in r.stderr and "frames" not in r.stderr and "cross-view truth" in r.stderr
    assert "3 views rendered" in r.stdout and "(sampler takes 4)" in r.stdout
    r = subprocess.run([sys.executable, "-m", "scenegen.cli", "-q", "render", "tiny.yaml", "-o", "out2"],
                       cwd=tmp_path, capture_output=True, text=True, env=ENV)
    assert r.returncode == 0 and r.stderr == ""
    r = subprocess.run([sys.executable, "-m", "scenegen.cli", "render", "tiny.yaml", "-o", "out"],
                       cwd=tmp_path, capture_output=True, text=True, env=ENV)
    assert r.returncode == 2 and "--resume" in r.stderr and "resume=True" not in r.stderr
    errors = [line for line in r.stderr.strip().splitlines() if not line.startswith("warning: ")]
    assert len(errors) == 1  # one line for the error (the spec's warnings come before it)


def test_scaled_camera_keeps_the_field_of_view():
    spec = load_spec(ROOT / "scenes/demo.yaml")
    for cs in spec.cameras.values():
        small = scaled_camera(cs, 160)
        cam, sc = cs.to_camera(), small.to_camera()
        s = (sc.width / cam.width, sc.height / cam.height)
        X = np.array([[0.1, -0.05, 1.0], [-0.3, 0.2, 2.0], [0.0, 0.0, 1.0]])
        # pixel edges scale: (u + 0.5) s = u' + 0.5 (OpenCV centres)
        assert np.allclose((cam.project(X) + 0.5) * s, sc.project(X) + 0.5, atol=1e-9)


def test_preview_of_the_demo_is_one_sheet_in_seconds(tmp_path):
    out = tmp_path / "demo.png"
    t0 = time.perf_counter()
    assert main(["-q", "preview", str(ROOT / "scenes/demo.yaml"), "-o", str(out)]) == 0
    seconds = time.perf_counter() - t0
    print(f"preview of scenes/demo.yaml: {seconds:.1f} s")
    sheet = cv2.imread(str(out), cv2.IMREAD_UNCHANGED)[..., ::-1]
    spec = load_spec(ROOT / "scenes/demo.yaml")
    views = resolve_views(spec)
    cam = scaled_camera(spec.cameras[views[0].camera], 160)
    row = LABEL_PX + cam.height + GAP_PX
    assert sheet.shape == (row * len(views), 4 * 160 + 3 * GAP_PX, 3)
    for k in range(len(views)):
        body = sheet[k * row + LABEL_PX: k * row + LABEL_PX + cam.height]
        depth, ids = body[:, 162:322], body[:, 486:646]
        # every pixel with a surface has an id colour and a depth colour, and the background neither
        assert np.array_equal(ids.any(-1), depth.any(-1))
    assert seconds < 60


def test_gallery_of_a_dataset(crossview_render, tmp_path):
    ds = Dataset(crossview_render[1])
    out = tmp_path / "g.png"
    assert main(["-q", "gallery", str(ds.root), "-o", str(out)]) == 0
    sheet = cv2.imread(str(out), cv2.IMREAD_UNCHANGED)[..., ::-1]
    page = (tmp_path / "g.html").read_text()
    assert "g.png" in page and all(v in page for v in ds.views)
    y = 0
    for v in ds.views:  # rows in the dataset's order; the ids tile holds exactly the ids' colours
        t = ds.truth(v)
        h = round(t["valid"].shape[0] * 160 / t["valid"].shape[1])
        ids = sheet[y + LABEL_PX: y + LABEL_PX + h, 486:646].reshape(-1, 3)
        want = {tuple(c) for c in id_colours(np.unique(t["instance_id"]))}
        assert {tuple(c) for c in np.unique(ids, axis=0)} <= want | {(255, 255, 255)}
        y += LABEL_PX + h + GAP_PX
    assert y == sheet.shape[0]
    hostile = html_page("<script>alert(1)</script>", "a'b.png", [{"view": "<b>", "camera": "&", "size": "1", "truth": ""}])
    assert "<script>" not in hostile and html.escape("<script>alert(1)</script>") in hostile and "<b>" not in hostile


def test_info_json(crossview_render, capsys):
    ds = Dataset(crossview_render[1])
    assert main(["info", str(ds.root), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["views_complete"] == len(ds.views) and doc["crossview"] is True
    for v in ds.views:
        cam, pose = ds.camera(v)
        assert doc["views"][v]["camera"]["K"] == cam.K.tolist()
        assert np.allclose(doc["views"][v]["centre_m"], pose.inverse().t)


def test_mitsuba_log_lines_in_our_words(capfd):
    from scenegen.render.backend import load_mitsuba, renderer_log_line, set_renderer_log

    mi = load_mitsuba("llvm_ad_rgb")
    try:
        mi.load_dict({"type": "ldsampler", "sample_count": 3})  # Mitsuba warns: it rounds to 4
        out, err = capfd.readouterr()
        assert err.strip() == ("scenegen: Mitsuba warning: [LowDiscrepancySampler] Sample count should be square "
                               "and power of two, rounding to 4") and "WARN" not in out + err
        set_renderer_log(False)  # -q
        mi.load_dict({"type": "ldsampler", "sample_count": 5})
        assert capfd.readouterr() == ("", "")
    finally:
        set_renderer_log(True)
    assert renderer_log_line("error", "2026-01-01 00:00:00 ERROR [Scene] no shapes") == \
        "scenegen: Mitsuba error: [Scene] no shapes"
