"""Progress in a log (stderr not a terminal: CI, a file, a pipe): a line at the start, at least
every LOG_EVERY_S seconds while the stage works (also within one long item) and at the end."""
import re
import subprocess
import sys
import time

import pytest

from scenegen.pipeline.progress import LOG_EVERY_S, ViewProgress

LINE = re.compile(r"^scenegen: (.+): (\d+)/(\d+) (\w+) \((\d+\.\d) s, \d+\.\d\d \4/s\)$")


def test_a_log_gets_lines_while_a_long_item_works(capsys):
    with ViewProgress(True, 3, label="rendering views", every_s=0.1) as bar:
        for _ in range(3):
            time.sleep(0.35)  # one item: longer than three intervals
            bar.advance()
    lines = capsys.readouterr().err.splitlines()
    parsed = [LINE.match(x) for x in lines]
    assert all(parsed), lines
    done = [int(m.group(2)) for m in parsed]
    t = [float(m.group(5)) for m in parsed]
    assert done[0] == 0 and done[-1] == 3 and done == sorted(done)
    assert done.count(0) >= 3  # the first item alone was reported several times while it ran
    gaps = [b - a for a, b in zip(t, t[1:])]
    assert max(gaps) <= 0.1 + 0.15, gaps  # the timer's interval, plus scheduling on a busy machine
    assert {m.group(1) for m in parsed} == {"rendering views"} and {m.group(4) for m in parsed} == {"views"}


def test_disabled_or_empty_prints_nothing(capsys):
    for enabled, total in ((False, 3), (True, 0)):
        with ViewProgress(enabled, total, every_s=0.01) as bar:
            time.sleep(0.05)
            bar.advance()
    assert capsys.readouterr().err == ""


def test_the_log_interval_is_at_most_ten_seconds():
    assert 0 < LOG_EVERY_S <= 10


@pytest.mark.render
def test_scenegen_render_into_a_pipe_writes_progress_lines(tmp_path):
    spec = tmp_path / "s.yaml"
    spec.write_text("name: s\nrender: {spp: 4}\nobjects:\n  - {name: b, shape: {type: sphere, radius: 0.3}}\n"
                    "lights:\n  - {type: constant, radiance: 1.0}\ncameras:\n  cam: {size: [32, 24], fov_deg: 60}\n"
                    "views:\n  - {camera: cam, orbit: {radius_m: 2, count: 2}}\n")
    r = subprocess.run([sys.executable, "-m", "scenegen.cli", "render", str(spec), "-o", str(tmp_path / "o")],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    lines = [m.groups() for m in map(LINE.match, r.stderr.splitlines()) if m]
    assert ("rendering views", "0", "2", "views") in [g[:4] for g in lines]
    assert ("rendering views", "2", "2", "views") in [g[:4] for g in lines]
