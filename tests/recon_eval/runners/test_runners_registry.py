"""The method tables: production methods and deliberately broken ones (faults), looked up by name."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.runners import FAULTS, METHODS, faults, method

ROOT = Path(__file__).resolve().parents[3]


def test_run_bad_input_exit_2(tmp_path):
    r = subprocess.run([sys.executable, "-m", "recon_eval", "run", "opencv-f-ransak", str(tmp_path), "-o",
                        str(tmp_path / "o")], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and "did you mean 'opencv-f-ransac'" in r.stderr and "Traceback" not in r.stderr


def test_runners_import_no_mitsuba():
    code = ("import sys, recon_eval.runners, recon_eval.ci.gates, recon_eval.ci.leaderboard, recon_eval.cli.ci\n"
            "from recon_eval.runners import calibration, stereo, twoview, pnp, colmap\n"
            "assert not any(m.split('.')[0] in ('mitsuba', 'drjit') for m in sys.modules), 'mitsuba imported'\n")
    assert subprocess.run([sys.executable, "-c", code], cwd=ROOT).returncode == 0


def test_faults_are_apart_from_the_production_methods_and_run_by_name():
    assert set(FAULTS) == {"broken-calib-cx", "broken-f-transposed"}
    assert not set(FAULTS) & set(METHODS) and not any(m.name.startswith("broken") for m in METHODS.values())
    assert all(m.fault and m.module == "faults" for m in FAULTS.values())
    assert not any(m.fault for m in METHODS.values())
    assert method("broken-calib-cx") is FAULTS["broken-calib-cx"]
    assert method("opencv-f-ransac") is METHODS["opencv-f-ransac"]
    with pytest.raises(InputError, match="did you mean 'broken-calib-cx'"):
        method("broken-calib-cy")


def test_run_list_marks_the_faults():
    r = subprocess.run([sys.executable, "-m", "recon_eval", "run", "--list"], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(lines) == len(METHODS) + len(FAULTS)
    faults = [ln for ln in lines if "[fault]" in ln]
    assert [ln.split()[0] for ln in faults] == list(FAULTS) and lines[-len(FAULTS):] == faults


def test_fault_functions_plant_their_error():
    K = np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]])
    planted = faults.shift_cx(K)
    assert planted[0, 2] == 320 + faults.CX_SHIFT_PX and K[0, 2] == 320  # a copy, cx only
    np.testing.assert_array_equal(np.delete(planted.ravel(), 2), np.delete(K.ravel(), 2))
