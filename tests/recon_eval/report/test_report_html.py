"""The HTML report: one self-contained, valid HTML file with the numbers and embedded PNG figures."""
import base64
import re
from html.parser import HTMLParser

import numpy as np

from recon_eval.cli import main


VOID = {"meta", "img", "br", "hr", "link", "input"}


class _Checker(HTMLParser):
    """Collects tags, checks nesting of non-void elements, collects image sources and text."""

    def __init__(self):
        super().__init__()
        self.stack, self.errors, self.imgs, self.text, self.tags = [], [], [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag == "img":
            self.imgs.append(dict(attrs)["src"])
        elif tag not in VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if not self.stack or self.stack.pop() != tag:
            self.errors.append(f"unbalanced </{tag}>")

    def handle_data(self, data):
        self.text.append(data)


def check_html(path):
    """Parse; return (checker, decoded PNG images). Fails on broken structure or external refs."""
    import cv2

    s = path.read_text(encoding="utf-8")
    assert s.startswith("<!DOCTYPE html>")
    c = _Checker()
    c.feed(s)
    c.close()
    assert not c.errors and not c.stack, (c.errors, c.stack)
    assert {"html", "head", "body", "title", "table"} <= set(c.tags)
    assert not re.search(r'(src|href)="(?!data:)', s)  # self-contained: no external resources
    pngs = []
    for src in c.imgs:
        assert src.startswith("data:image/png;base64,")
        raw = base64.b64decode(src.split(",", 1)[1], validate=True)
        assert raw[:8] == b"\x89PNG\r\n\x1a\n"
        img = cv2.imdecode(np.frombuffer(raw, np.uint8), cv2.IMREAD_UNCHANGED)
        assert img is not None and img.shape[0] > 100 and img.shape[1] > 100
        pngs.append(raw)
    return c, pngs


def test_depth_report_has_heatmaps_and_numbers(plane_dataset, tmp_path, capsys):
    from recon_eval.readers.scenegen_dataset import read_dataset

    root, _ = plane_dataset
    ds = read_dataset(root)
    (tmp_path / "est").mkdir()
    e = ds.depth("left_000") * 1.1
    e[:5, :5] = np.nan
    np.save(tmp_path / "est" / "left_000.npy", e)
    assert main(["depth", str(tmp_path / "est"), str(root), "--view", "left_000", "--quiet",
                 "--html", str(tmp_path / "r.html")]) == 0
    c, pngs = check_html(tmp_path / "r.html")
    text = " ".join(c.text)
    assert len(pngs) == 2 and "Depth error: left_000" in text and "Cumulative relative depth error" in text
    assert "abs_rel" in text and "0.1" in text  # the number itself, from the table

    from scenegen.dataset.codecs import write_pfm

    d = ds.disparity("left_000") + rng_noise((30, 40))
    write_pfm(tmp_path / "d.pfm", d)
    assert main(["disparity", str(tmp_path / "d.pfm"), str(root), "--view", "left_000", "--quiet",
                 "--html", str(tmp_path / "d.html")]) == 0
    c, pngs = check_html(tmp_path / "d.html")
    assert len(pngs) == 2 and "d1_all_occ_pct" in " ".join(c.text)


def rng_noise(shape):
    return np.random.default_rng(0).normal(0, 1.0, shape)


def test_poses_cloud_fmatrix_calibration_reports(plane_dataset, tmp_path, capsys):
    from scenegen.geometry.pose import Rigid3
    from scenegen.geometry.twoview import fundamental
    from recon_eval.readers.nerf import write_nerf_transforms
    from recon_eval.readers.opencv_calib import write_opencv_calibration
    from recon_eval.readers.ply import write_point_cloud_ply
    from recon_eval.readers.scenegen_dataset import read_dataset

    root, cams = plane_dataset
    write_nerf_transforms(tmp_path / "t.json", read_dataset(root).poses)
    assert main(["poses", str(tmp_path / "t.json"), str(root), "--alignment", "none", "--quiet",
                 "--html", str(tmp_path / "p.html")]) == 0
    c, pngs = check_html(tmp_path / "p.html")
    assert len(pngs) == 4 and "Per-camera pose errors" in " ".join(c.text)

    rng = np.random.default_rng(1)
    write_point_cloud_ply(tmp_path / "rec.ply", np.c_[rng.uniform(-2, 2, (2000, 2)), rng.normal(0, 0.003, 2000)])
    assert main(["cloud", str(tmp_path / "rec.ply"), str(root), "--tau", "0.005", "--gt-samples", "20000", "--quiet",
                 "--html", str(tmp_path / "c.html")]) == 0
    c, pngs = check_html(tmp_path / "c.html")
    assert len(pngs) == 2 and "Precision / recall / F-score vs tau" in " ".join(c.text)

    (c1, p1), (c2, p2) = cams["left_000"], cams["right_000"]
    rel = p2 @ p1.inverse()
    from scipy.spatial.transform import Rotation

    dR = Rotation.from_rotvec([0.0, 0.0, 0.02]).as_matrix()  # a wrong but rank-2 F
    F = fundamental(c1.K, c2.K, Rigid3(dR @ rel.R, rel.t))
    np.savetxt(tmp_path / "F.txt", F)
    assert main(["fmatrix", str(tmp_path / "F.txt"), "--dataset", str(root), "--views", "left_000", "right_000",
                 "--quiet", "--html", str(tmp_path / "f.html")]) == 0
    c, pngs = check_html(tmp_path / "f.html")
    assert len(pngs) == 2 and "Epipolar lines" in " ".join(c.text) and "sampson_rms_px" in " ".join(c.text)
    (tmp_path / "epipolar.png").write_bytes(pngs[1])

    write_opencv_calibration(tmp_path / "k.yaml", cams["free_000"][0].__class__(
        "opencv", 40, 30, 42.5, 41.0, 19.0, 15.0, 0.0, (-0.04, 0.01, 0.001, -0.001, 0.0)))
    assert main(["calibration", str(tmp_path / "k.yaml"), str(root), "--view", "free_000", "--quiet",
                 "--html", str(tmp_path / "k.html")]) == 0
    c, pngs = check_html(tmp_path / "k.html")
    assert len(pngs) == 2 and "fx_abs_err_px" in " ".join(c.text) and "0.5" in " ".join(c.text)


def test_no_matplotlib_at_import():
    import subprocess
    import sys

    code = ("import sys, recon_eval.cli, recon_eval.report.html, recon_eval.report.plots, recon_eval.cli.cloud, "
            "recon_eval.cli.maps, recon_eval.cli.features\n"
            "assert 'matplotlib' not in sys.modules, 'matplotlib imported eagerly'\n")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_reports_get_the_usual_file_permissions(tmp_path):
    """JSON and HTML reports are written atomically with 0o666 minus the umask, like any file (a
    bare mkstemp would leave them readable by their owner only)."""
    import os

    from recon_eval.report.html import write_html_atomic
    from recon_eval.report.document import write_json_atomic

    old = os.umask(0o022)
    try:
        write_json_atomic(tmp_path / "r.json", {"a": 1})
        write_html_atomic(tmp_path / "r.html", "<!DOCTYPE html>")
    finally:
        os.umask(old)
    for name in ("r.json", "r.html"):
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o644
    assert (tmp_path / "r.json").read_text() == '{\n  "a": 1\n}\n'
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary file left
